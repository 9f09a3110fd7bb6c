#include "renderer/sweep/sweep_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "renderer/plot/vector_plot.h"

#include "renderer/core/errors/error.h"
#include "renderer/sweep/metrics/sweep_metrics.h"
#include "renderer/sweep/metrics/sweep_plots.h"
#include "renderer/sweep/store/sweep_store.h"
#include "renderer/sweep/sweep_point.h"

namespace ofl {
namespace {

std::string html_escape(const std::string& s) { return svg_escape(s); }

std::string number_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

std::string short_number(const nlohmann::ordered_json& v) {
  if (v.is_null()) return "&ndash;";
  if (v.is_number()) {
    char b[32];
    std::snprintf(b, sizeof b, "%.4g", v.get<double>());
    return b;
  }
  return html_escape(v.is_string() ? v.get<std::string>() : v.dump());
}

const nlohmann::ordered_json& metric(const nlohmann::ordered_json& r, const std::string& name) {
  static const nlohmann::ordered_json null_value = nullptr;
  auto it = r["metrics"].find(name);
  return it == r["metrics"].end() ? null_value : *it;
}

const char* kStyle = R"(
body { font-family: "DejaVu Sans", Arial, sans-serif; margin: 24px; color: #222; }
h1 { font-size: 22px; } h2 { font-size: 18px; margin-top: 32px; } h3 { font-size: 15px; }
table.points { border-collapse: collapse; font-size: 12px; }
table.points td, table.points th { border: 1px solid #ccc; padding: 3px 6px; text-align: right; vertical-align: middle; }
table.points th { background: #f3f3f3; }
table.grid td { vertical-align: top; padding: 0; }
.figs { display: flex; flex-wrap: wrap; gap: 12px; }
figure { margin: 0; border: 1px solid #ddd; padding: 6px; font-size: 11px; }
figcaption { max-width: 320px; }
.legend span { display: inline-block; margin-right: 14px; font-size: 12px; }
.swatch { display: inline-block; width: 12px; height: 12px; margin-right: 4px; vertical-align: middle; }
.note { color: #555; font-size: 13px; max-width: 900px; }
)";

std::string swatch(const Rgba& c) {
  char b[96];
  std::snprintf(b, sizeof b, "<i class=\"swatch\" style=\"background:#%02x%02x%02x\"></i>", int(std::lround(c.r * 255)),
                int(std::lround(c.g * 255)), int(std::lround(c.b * 255)));
  return b;
}

}  // namespace

std::vector<std::string> metric_columns(const SweepSpec& spec) {
  std::vector<std::string> c;
  for (auto& r : spec.rois)
    for (auto& m : roi_metric_names()) c.push_back(r.name + "." + m);
  if (!spec.metrics.lesion_roi.empty())
    for (auto& m : contrast_metric_names()) c.push_back("contrast." + m);
  return c;
}

std::string csv_field(const nlohmann::ordered_json& v) {
  if (v.is_null()) return "";
  if (v.is_number_integer()) return v.dump();
  if (v.is_number()) return std::isfinite(v.get<double>()) ? number_text(v.get<double>()) : "";
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

void drop_report_only_members(nlohmann::ordered_json& result) {
  for (const char* k : {"scatter", "reference", "thumbnail_png_base64", "roi_png_base64", "identity"}) result.erase(k);
}

namespace {

using Results = std::vector<const nlohmann::ordered_json*>;

// The HTML page being written, with a counter that makes each inline plot's ids unique.
struct ReportPage {
  std::ostringstream h;
  int plots = 0;
  void add_plot(const VectorPlot& p) {
    h << inline_svg(p, std::string("p").append(std::to_string(plots)).append("_"));
    ++plots;
  }
};

// results.csv (one row per finished point, every metric) and results.json (the results without
// the members only the report draws).
void write_result_tables(const SweepSpec& spec, const Results& done, const ReportFiles& files) {
  const auto columns = metric_columns(spec);
  std::ostringstream csv;
  csv << "index,key";
  for (auto& p : spec.parameters) csv << "," << p.name;
  csv << ",spp,relative_noise,render_seconds,render_cached,saturated_fraction";
  for (auto& c : columns) csv << "," << c;
  csv << "\n";
  nlohmann::ordered_json arr = nlohmann::ordered_json::array();
  for (const auto* r : done) {
    csv << (*r)["index"].get<int>() << "," << (*r)["key"].get<std::string>();
    for (auto& p : spec.parameters) csv << "," << csv_field((*r)["parameters"][p.name]);
    csv << "," << csv_field((*r)["render"]["spp"]) << "," << csv_field((*r)["render"]["relative_noise"]) << ","
        << csv_field((*r)["render"]["seconds"]) << ","
        << (r->contains("render_cached") ? csv_field((*r)["render_cached"]) : std::string()) << ","
        << csv_field((*r)["camera"]["saturated_fraction"]);
    for (auto& c : columns) csv << "," << csv_field(metric(*r, c));
    csv << "\n";
    nlohmann::ordered_json o;
    for (const char* k : {"index", "key", "label", "parameters", "metrics", "render", "render_cached", "render_key", "camera", "led_band_nm", "warnings"})
      if (r->contains(k)) o[k] = (*r)[k];
    arr.push_back(o);
  }
  write_file_atomic(files.csv, csv.str());
  write_file_atomic(files.json, arr.dump(1) + "\n");
}

// The page's head and the sweep's summary paragraph.
void write_page_head(std::ostringstream& h, const SweepSpec& spec, size_t points, size_t finished) {
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>oralfluor sweep " << html_escape(spec.name)
    << "</title><style>" << kStyle << "</style></head><body>\n";
  h << "<h1>Sweep &ldquo;" << html_escape(spec.name) << "&rdquo;</h1>\n";
  if (!spec.description.empty()) h << "<p class=\"note\">" << html_escape(spec.description) << "</p>\n";
  h << "<p>" << finished << " of " << points << " design points finished"
    << (finished < points ? " (the rest are missing from this report; run the sweep again to finish them)" : "")
    << ". Scene <code>" << html_escape(spec.scene.string()) << "</code>, camera <code>" << html_escape(spec.camera.string())
    << "</code>, " << (spec.design.type == DesignSpec::Type::kGrid ? "full grid" : "Latin hypercube") << ". Data: <a href=\"results.csv\">results.csv</a>, "
    << "<a href=\"results.json\">results.json</a>. Plots rendered: <span id=\"plots-rendered\">0</span>.</p>\n";
}

// The points table: thumbnail, parameters and a few metrics of the first ROI.
void write_points_table(std::ostringstream& h, const SweepSpec& spec, const Results& shown, const std::string& shown_note) {
  const std::vector<std::string> table_metrics = {"irr_cv", "irr_p5_p95", "r_std", "g_std", "ellipse_area", "share_leak", "snr_G"};
  const std::string first_roi = spec.rois.empty() ? "" : spec.rois.front().name;
  h << "<h2 id=\"points\">Points</h2>\n<table class=\"points\"><tr><th>#</th><th>preview</th>";
  for (auto& p : spec.parameters) h << "<th>" << html_escape(p.name) << "</th>";
  for (auto& m : table_metrics) h << "<th>" << html_escape(first_roi + "." + m) << "</th>";
  h << "<th>spp</th><th>noise</th></tr>\n";
  for (const auto* r : shown) {
    h << "<tr><td>" << (*r)["index"].get<int>() << "</td><td><img alt=\"point " << (*r)["index"].get<int>()
      << "\" src=\"data:image/png;base64," << r->value("thumbnail_png_base64", std::string()) << "\"></td>";
    for (auto& p : spec.parameters) h << "<td>" << short_number((*r)["parameters"][p.name]) << "</td>";
    for (auto& m : table_metrics) h << "<td>" << short_number(metric(*r, first_roi + "." + m)) << "</td>";
    h << "<td>" << (*r)["render"]["spp"].get<int>() << "</td><td>" << short_number((*r)["render"]["relative_noise"]) << "</td></tr>\n";
  }
  h << "</table>\n" << shown_note;
}

// One metric against one parameter over every finished point.
VectorPlot metric_against_parameter(const std::string& column, size_t pi, const SweepSpec& spec,
                                    const std::vector<DesignPoint>& design,
                                    const std::vector<std::optional<nlohmann::ordered_json>>& results) {
  const auto& par = spec.parameters[pi];
  MetricPlotSpec ps;
  ps.title = column;
  ps.x_label = par.name;
  bool numeric = par.numeric();
  if (!numeric)
    for (auto& v : par.values) ps.categories.push_back(value_text(v));
  std::vector<MetricSample> samples;
  for (size_t i = 0; i < results.size(); ++i) {
    if (!results[i]) continue;
    const auto& y = metric(*results[i], column);
    if (!y.is_number()) continue;
    MetricSample s;
    s.level = design[i].level[pi];
    s.x = numeric ? design[i].values[pi].get<double>() : double(s.level);
    s.y = y.get<double>();
    samples.push_back(s);
  }
  // Categorical axes get room for their labels.
  int width = ps.categories.empty() ? 300 : std::max(300, 70 + 84 * int(ps.categories.size()));
  return metric_plot(ps, samples, width);
}

// Metrics against parameters: per ROI a table of plots, one row per report metric, one column per
// parameter (also written under plots/ with plot_files).
void write_metric_section(ReportPage& page, const SweepSpec& spec, const std::vector<DesignPoint>& design,
                          const std::vector<std::optional<nlohmann::ordered_json>>& results, const std::filesystem::path& out,
                          const ReportOptions& options) {
  std::ostringstream& h = page.h;
  h << "<h2 id=\"metrics\">Metrics against parameters</h2>\n<p class=\"note\">One dot per finished point; the red line joins the "
       "mean at each level of a numeric parameter (averaged over the other parameters); for named levels a red bar marks each level's mean. Metric names are defined in "
       "docs/sweep-format.md.</p>\n";
  std::error_code ec;
  if (options.plot_files) std::filesystem::create_directories(out / "plots", ec);
  for (auto& roi : spec.rois) {
    h << "<h3>ROI " << html_escape(roi.name) << "</h3>\n<table class=\"grid\">\n";
    for (auto& mname : spec.report.metrics) {
      std::string col = roi.name + "." + mname;
      h << "<tr>";
      for (size_t pi = 0; pi < spec.parameters.size(); ++pi) {
        VectorPlot p = metric_against_parameter(col, pi, spec, design, results);
        h << "<td>";
        page.add_plot(p);
        h << "</td>";
        if (options.plot_files) {
          auto stem = out / "plots" / (col + "__" + spec.parameters[pi].name);
          p.write_svg(stem.string() + ".svg");
          p.write_png(stem.string() + ".png");
        }
      }
      h << "</tr>\n";
    }
    h << "</table>\n";
  }
}

// Which ROIs the chromaticity plots draw (report.scatter_rois, default all), in which colour.
ScatterStyle scatter_style(const SweepSpec& spec) {
  ScatterStyle style;
  style.noise_free = spec.report.scatter_noise_free;
  for (size_t k = 0; k < spec.rois.size(); ++k) {
    const std::string& name = spec.rois[k].name;
    if (spec.report.scatter_rois.empty() ||
        std::find(spec.report.scatter_rois.begin(), spec.report.scatter_rois.end(), name) != spec.report.scatter_rois.end()) {
      style.rois.push_back(name);
      style.color.push_back(k);
    }
  }
  return style;
}

// One point's figure: its chromaticity plot and its two thumbnails (also written under plots/).
void write_point_figure(ReportPage& page, const nlohmann::ordered_json& r, const ScatterStyle& style, const ChromaWindow& win,
                        const std::filesystem::path& out, const ReportOptions& options) {
  std::ostringstream& h = page.h;
  h << "<figure>";
  VectorPlot cp = point_chroma_plot(r, style, win);
  page.add_plot(cp);
  if (options.plot_files) {
    const std::string idx = std::to_string(r["index"].get<int>());
    auto stem = out / "plots" / ("chroma_" + idx);
    cp.write_svg(stem.string() + ".svg");
    cp.write_png(stem.string() + ".png");
    for (const char* k : {"thumbnail", "roi"})
      if (r.contains(std::string(k) + "_png_base64"))
        write_file_atomic(out / "plots" / (std::string(k == std::string("roi") ? "rois_" : "preview_") + idx + ".png"),
                          base64_decode(r[std::string(k) + "_png_base64"].get<std::string>()));
  }
  h << "<figcaption><img alt=\"\" style=\"float:right;width:96px\" src=\"data:image/png;base64,"
    << r.value("thumbnail_png_base64", std::string()) << "\">";
  if (r.contains("roi_png_base64"))
    h << "<img alt=\"ROIs\" title=\"ROIs\" style=\"float:right;width:96px;margin-right:4px\" src=\"data:image/png;base64,"
      << r["roi_png_base64"].get<std::string>() << "\">";
  h << html_escape(r.value("label", std::string())) << "</figcaption></figure>\n";
}

// Chromaticity of each shown point, in one window common to all, with the legend above.
void write_chroma_section(ReportPage& page, const SweepSpec& spec, const Results& shown, const std::string& shown_note,
                          const std::filesystem::path& out, const ReportOptions& options) {
  std::ostringstream& h = page.h;
  ScatterStyle style = scatter_style(spec);
  h << "<h2 id=\"chromaticity\">Chromaticity of each point</h2>\n<p class=\"note\">Cells (2x2 CFA) of each ROI in the (r, g) plane "
    << (style.noise_free ? "from the noise-free expected electrons" : "from the raw")
    << ", with each ROI's mean (+) and 95 % ellipse; dashed lines: tongue reflectance plus increasing "
       "fluorophore concentration under this point's LED through its camera (black square: no fluorophore), as "
       "<code>oralfluor chroma</code> draws them. All panels share one window.</p>\n<p class=\"legend\">";
  for (size_t k = 0; k < style.rois.size(); ++k)
    h << "<span>" << swatch(roi_color(style.color[k])) << "ROI " << html_escape(style.rois[k]) << "</span>";
  if (!shown.empty() && shown.front()->contains("reference")) {
    const auto& lines = (*shown.front())["reference"]["lines"];
    for (size_t i = 0; i < lines.size(); ++i)
      h << "<span>" << swatch(line_color(i)) << html_escape(lines[i]["fluorophore"].get<std::string>()) << "</span>";
  }
  h << "</p>\n" << shown_note << "<div class=\"figs\">\n";
  ChromaWindow win = common_chroma_window(shown, style);
  for (const auto* r : shown) write_point_figure(page, *r, style, win, out, options);
  h << "</div>\n";
}

// Counts plots that were laid out with a size and hold drawing: proves the page rendered them.
const char* kPlotCountScript = R"(<script>
(function () {
  function count() {
    var n = 0;
    document.querySelectorAll('svg.plot').forEach(function (s) {
      var b = s.getBoundingClientRect();
      if (b.width > 0 && b.height > 0 && s.querySelector('circle, polyline, polygon, text')) n++;
    });
    var el = document.getElementById('plots-rendered');
    el.textContent = String(n);
    el.setAttribute('data-count', String(n));
  }
  count();
  window.addEventListener('load', count);
})();
</script>
)";

}  // namespace

ReportFiles write_sweep_report(const SweepSpec& spec, const std::vector<DesignPoint>& design,
                               const std::vector<std::optional<nlohmann::ordered_json>>& results,
                               const std::filesystem::path& out, const ReportOptions& options) {
  ReportFiles files;
  files.csv = out / "results.csv";
  files.json = out / "results.json";
  files.html = out / "report.html";
  Results done;
  for (auto& r : results)
    if (r) done.push_back(&*r);
  // Thumbnails and scatter plots for the first finished points only: a large design's page stays
  // a page (every point is in the CSV, the JSON and the metric plots).
  const Results shown(done.begin(), done.begin() + std::min(done.size(), kReportPointsShown));
  const std::string shown_note = shown.size() < done.size() ? "<p class=\"note\">The first " + std::to_string(shown.size()) +
                                                                  " of the " + std::to_string(done.size()) +
                                                                  " finished points; results.csv has them all.</p>\n"
                                                            : std::string();
  write_result_tables(spec, done, files);

  ReportPage page;
  write_page_head(page.h, spec, design.size(), done.size());
  write_points_table(page.h, spec, shown, shown_note);
  write_metric_section(page, spec, design, results, out, options);
  write_chroma_section(page, spec, shown, shown_note, out, options);
  page.h << kPlotCountScript;
  page.h << "</body></html>\n";
  write_file_atomic(files.html, page.h.str());
  files.plots = page.plots;
  return files;
}

}  // namespace ofl
