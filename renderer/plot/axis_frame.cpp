#include "renderer/plot/axis_frame.h"

#include <algorithm>
#include <cmath>

#include "renderer/plot/plot_axis.h"

namespace ofl {
namespace {

void draw_x_ticks(VectorPlot& p, const AxisFrame& f, const AxisTicks& t, double step) {
  if (!t.categories.empty()) {
    for (size_t i = 0; i < t.categories.size(); ++i) {
      auto a = f.map(double(i), f.y0);
      std::string s = t.categories[i];
      if (t.max_category_chars && s.size() > t.max_category_chars) s = s.substr(0, t.max_category_chars - 1) + "~";
      p.text({a[0], a[1] + t.x_label_dy}, s, t.font, t.text, TextAnchor::kMiddle);
    }
    return;
  }
  for (double v : axis_ticks(f.x0, f.x1, step)) {
    auto a = f.map(v, f.y0), b = f.map(v, f.y1);
    p.polyline({a, b}, t.grid, 1);
    p.text({a[0], a[1] + t.x_label_dy}, tick_label(v, step), t.font, t.text, TextAnchor::kMiddle);
  }
}

void draw_y_ticks(VectorPlot& p, const AxisFrame& f, const AxisTicks& t, double step) {
  for (double v : axis_ticks(f.y0, f.y1, step)) {
    auto a = f.map(f.x0, v), b = f.map(f.x1, v);
    p.polyline({a, b}, t.grid, 1);
    p.text({a[0] - t.y_label_dx, a[1] + 4}, tick_label(v, step), t.font, t.text, TextAnchor::kEnd);
  }
}

}  // namespace

void draw_axis_ticks(VectorPlot& p, const AxisFrame& f, const AxisTicks& t) {
  const bool x = t.x_target > 0 || !t.categories.empty(), y = t.y_target > 0;
  double xs = t.x_target > 0 ? nice_tick_step(f.x1 - f.x0, t.x_target) : 1;
  double ys = y ? nice_tick_step(f.y1 - f.y0, t.y_target) : 1;
  if (t.shared_step) xs = ys = nice_tick_step(std::max(f.x1 - f.x0, f.y1 - f.y0), t.x_target);
  if (t.y_first && y) draw_y_ticks(p, f, t, ys);
  if (x) draw_x_ticks(p, f, t, xs);
  if (!t.y_first && y) draw_y_ticks(p, f, t, ys);
}

void draw_frame_outline(VectorPlot& p, const AxisFrame& f, Rgba color, double width, Rgba fill) {
  p.rect(f.x, f.y, f.w, f.h, fill, color, width);
}

std::vector<Point2> ellipse_outline(const AxisFrame& f, double cx, double cy, double a, double b, double angle_rad, int segments) {
  std::vector<Point2> pts;
  for (int k = 0; k <= segments; ++k) {
    double t = 2 * 3.14159265358979323846 * k / segments, u = a * std::cos(t), v = b * std::sin(t);
    pts.push_back(f.map(cx + u * std::cos(angle_rad) - v * std::sin(angle_rad), cy + u * std::sin(angle_rad) + v * std::cos(angle_rad)));
  }
  return pts;
}

}  // namespace ofl
