// A plot's frame, drawn the same way by every plot (charts, chromaticity plots, sweep reports):
// the data rectangle on the picture and the data range it shows, its grid lines and tick labels
// at "nice" steps (plot_axis.h), its outline, and ellipses mapped into it.
#pragma once
#include <string>
#include <vector>

#include "renderer/plot/vector_plot.h"

namespace ofl {

struct AxisFrame {
  double x = 0, y = 0, w = 1, h = 1;      // the data rectangle, pixels
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;  // the data range it shows
  Point2 map(double vx, double vy) const { return {x + (vx - x0) / (x1 - x0) * w, y + h - (vy - y0) / (y1 - y0) * h}; }
  ClipRect clip() const { return {x, y, x + w, y + h}; }
};

struct AxisTicks {
  int x_target = 6, y_target = 5;  // about this many intervals; 0: no ticks on that axis
  bool shared_step = false;        // one step for both axes, from the larger range (equal-scale plots)
  bool y_first = false;            // draw the y grid before the x grid
  double font = 12;                // tick label size
  double x_label_dy = 16;          // x labels this far below the frame
  double y_label_dx = 6;           // y labels this far left of the frame
  Rgba grid = rgb_hex(0xe4e4e4), text = rgb_hex(0x222222);
  // Non-empty: a categorical x axis with these labels at x = 0, 1, ... (no grid lines), cut to
  // `max_category_chars` with a "~" when longer (0: never cut).
  std::vector<std::string> categories;
  size_t max_category_chars = 0;
};

// Grid lines and tick labels of both axes.
void draw_axis_ticks(VectorPlot& p, const AxisFrame& f, const AxisTicks& t);

// The frame's outline.
void draw_frame_outline(VectorPlot& p, const AxisFrame& f, Rgba color, double width, Rgba fill = {0, 0, 0, 0});

// The outline of the ellipse with centre (cx, cy), semi-axes a, b and the a axis at angle_rad
// from the x axis (data units), as `segments` + 1 points on the picture (closed).
std::vector<Point2> ellipse_outline(const AxisFrame& f, double cx, double cy, double a, double b, double angle_rad, int segments);

}  // namespace ofl
