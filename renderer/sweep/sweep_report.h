// What a sweep writes from its finished points (missing points are left out, so a partial sweep
// still has a report):
//   results.csv   one row per finished point: index, key, every parameter, render statistics,
//                 every metric of every ROI ("<roi>.<metric>") and the lesion contrast
//                 ("contrast.<metric>"); empty cells where a metric is undefined
//   results.json  the same as an array of objects (parameters, metrics, render, camera)
//   report.html   a static page that opens from disk without a server or any external resource:
//                 a table of points with thumbnails (PNG as data: URIs), every report metric of every
//                 ROI against every parameter (inline SVG), each point's chromaticity scatter with the
//                 fluorophore reference lines; a small inline script counts the rendered plots into
//                 the element #plots-rendered (tests read it through headless Chromium)
// Optionally the metric plots also as SVG + PNG files under plots/ (for documentation).
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/design/sweep_spec.h"

namespace ofl {

// The points table and the per-point chromaticity plots show the first this many finished points.
constexpr size_t kReportPointsShown = 500;

// What the report needs of a point beyond the first kReportPointsShown: the heavy members
// (thumbnails, the ROIs' cells) removed, so a large design's results fit in memory.
void drop_report_only_members(nlohmann::ordered_json& result);

struct ReportFiles {
  std::filesystem::path csv, json, html;
  int plots = 0;  // SVG plots in the HTML
};

struct ReportOptions {
  bool plot_files = false;  // also write plots/<roi>.<metric>__<parameter>.{svg,png}
};

// `results[i]` is design point i's stored result, or nullopt when it is not finished.
ReportFiles write_sweep_report(const SweepSpec& spec, const std::vector<DesignPoint>& design,
                               const std::vector<std::optional<nlohmann::ordered_json>>& results,
                               const std::filesystem::path& out_dir, const ReportOptions& options = {});

// Metric columns in CSV order ("<roi>.<metric>", then "contrast.<metric>").
std::vector<std::string> metric_columns(const SweepSpec& spec);
// One CSV field (RFC 4180 quoting; numbers with 9 significant digits; null -> empty).
std::string csv_field(const nlohmann::ordered_json& v);

}  // namespace ofl
