// Minimal SVG charts for reports (line/scatter plots with bands, grouped bars, panels), written
// by hand so that reports need nothing at run time. Axes get "nice" ticks; NaN points break lines.
#pragma once
#include <optional>
#include <string>
#include <vector>

namespace ofl {

struct PlotSeries {
  std::vector<double> x, y;
  std::string color = "#1f77b4";
  double width = 1.5;
  double opacity = 1.0;
  bool dashed = false;
  bool line = true;
  bool markers = false;
  std::string label;  // shown in the legend when not empty
};

struct PlotBand {
  std::vector<double> x, lo, hi;
  std::string color = "#999999";
  double opacity = 0.25;
  std::string label;
};

struct Plot {
  std::string title, xlabel, ylabel;
  std::vector<PlotBand> bands;
  std::vector<PlotSeries> series;
  std::optional<double> xmin, xmax, ymin, ymax;
  bool zero_line = false;
  bool diagonal = false;  // y = x (predicted vs measured)
};

struct BarChart {
  std::string title, ylabel;
  std::vector<std::string> categories;
  std::vector<std::string> series_names, colors;
  std::vector<std::vector<double>> values;  // [series][category]
  std::vector<double> markers;              // optional per-category marker (e.g. a threshold), NaN = none
  std::string marker_label;
};

std::string svg_plot(const Plot& p, double width = 720, double height = 420);
std::string svg_bars(const BarChart& b, double width = 720, double height = 420);
// Panels laid out in `cols` columns, each panel_w x panel_h, with an overall title.
std::string svg_panels(const std::vector<Plot>& plots, int cols, double panel_w, double panel_h, const std::string& title);

// A colour from a fixed qualitative palette.
std::string palette(int i);

}  // namespace ofl
