// Report charts drawn onto a VectorPlot (so each is SVG and PNG): line and scatter plots with
// shaded bands, grouped bar charts with per-category markers, and panels of plots under one
// title. Axes get "nice" ticks (axis_frame.h); NaN points break lines.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "renderer/plot/vector_plot.h"

namespace ofl {

struct PlotSeries {
  std::vector<double> x, y;
  Rgba color = rgb_hex(0x1f77b4);
  double width = 1.5;
  double opacity = 1.0;
  bool dashed = false;
  bool line = true;
  bool markers = false;
  std::string label;  // shown in the legend when not empty
};

struct PlotBand {
  std::vector<double> x, lo, hi;
  Rgba color = rgb_hex(0x999999);
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
  std::vector<std::string> series_names;
  std::vector<Rgba> colors;                 // per series (palette.h when missing)
  std::vector<std::vector<double>> values;  // [series][category]
  std::vector<double> markers;              // optional per-category marker (e.g. a threshold), NaN = none
  std::string marker_label;
};

VectorPlot line_chart(const Plot& p, int width = 720, int height = 420);
VectorPlot bar_chart(const BarChart& b, int width = 720, int height = 420);
// Panels laid out in `cols` columns, each panel_w x panel_h, with an overall title.
VectorPlot chart_panels(const std::vector<Plot>& plots, int cols, int panel_w, int panel_h, const std::string& title);

}  // namespace ofl
