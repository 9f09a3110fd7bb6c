// The report's pictures, drawn with renderer/plot/ (so each is SVG for the HTML and PNG for docs):
//  - a metric against one parameter: one dot per finished point, the mean per level joined by a
//    line when the parameter has discrete levels (list, grid range or variants);
//  - one point's chromaticity: the cells of every ROI in the (r, g) plane, each ROI's mean and
//    95 % ellipse, and the fluorophore reference lines of that point's LED and camera (tongue
//    reflectance plus increasing fluorophore, oralfluor chroma's construction), in a window common
//    to all points so that they can be compared by eye.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/plot/vector_plot.h"

namespace ofl {

struct MetricSample {
  double x = 0;          // numeric parameter value, or the level index for categories
  double y = 0;
  int level = -1;        // level index (-1: continuous sample)
};

struct MetricPlotSpec {
  std::string title;           // e.g. "dorsum.irr_cv"
  std::string x_label;         // the parameter
  std::vector<std::string> categories;  // non-empty: a categorical x axis with these labels
  bool log_x = false;
};

VectorPlot metric_plot(const MetricPlotSpec& spec, const std::vector<MetricSample>& samples, int width = 300,
                       int height = 210);

struct ChromaWindow {
  double r0 = 0, r1 = 1, g0 = 0, g1 = 1;
};
// Which cells a scatter plot draws: these ROIs (each in roi_color(color[k])), raw or noise-free.
struct ScatterStyle {
  std::vector<std::string> rois;
  std::vector<size_t> color;
  bool noise_free = false;
};

// Spans the drawn cells of every result (robustly: 1st-99th percentile), with a margin.
ChromaWindow common_chroma_window(const std::vector<const nlohmann::ordered_json*>& results, const ScatterStyle& style);
VectorPlot point_chroma_plot(const nlohmann::ordered_json& result, const ScatterStyle& style, const ChromaWindow& window,
                             int width = 320, int height = 300);

// Colour of the k-th ROI / reference line (shared by the plots and the HTML legend).
Rgba roi_color(size_t k);
Rgba line_color(size_t k);

// The plot's SVG for inline use in HTML: class attribute added and clip-path ids made unique with
// `id_prefix` (ids of separate SVGs share one document namespace).
std::string inline_svg(const VectorPlot& plot, const std::string& id_prefix, const std::string& css_class = "plot");

}  // namespace ofl
