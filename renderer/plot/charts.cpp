#include "renderer/plot/charts.h"

#include <algorithm>
#include <cmath>

#include "renderer/plot/axis_frame.h"
#include "renderer/plot/palette.h"

namespace ofl {
namespace {

const Rgba kBlack = rgb_hex(0x000000), kText = rgb_hex(0x222222), kFrame = rgb_hex(0x444444), kLine = rgb_hex(0x555555);

Rgba with_alpha(Rgba c, double a) {
  c.a = static_cast<float>(a);
  return c;
}

void expand(double& lo, double& hi) {
  if (!(hi > lo)) {
    double c = std::isfinite(lo) ? lo : 0;
    lo = c - 1;
    hi = c + 1;
  }
}

// The data range a plot shows: every finite point of its series and bands, zero and the diagonal
// when drawn, the plot's own limits, a little room above and below.
void data_range(const Plot& p, double& xmin, double& xmax, double& ymin, double& ymax) {
  xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  auto take = [&](const std::vector<double>& xs, const std::vector<double>& ys) {
    for (size_t i = 0; i < xs.size() && i < ys.size(); ++i)
      if (std::isfinite(xs[i]) && std::isfinite(ys[i])) {
        xmin = std::min(xmin, xs[i]);
        xmax = std::max(xmax, xs[i]);
        ymin = std::min(ymin, ys[i]);
        ymax = std::max(ymax, ys[i]);
      }
  };
  for (auto& s : p.series) take(s.x, s.y);
  for (auto& b : p.bands) {
    take(b.x, b.lo);
    take(b.x, b.hi);
  }
  if (p.zero_line) { ymin = std::min(ymin, 0.0); ymax = std::max(ymax, 0.0); }
  if (p.diagonal) {
    double lo = std::min(xmin, ymin), hi = std::max(xmax, ymax), pad = 0.03 * (hi - lo);
    xmin = ymin = lo - pad;
    xmax = ymax = hi + pad;
  }
  if (p.xmin) xmin = *p.xmin;
  if (p.xmax) xmax = *p.xmax;
  if (p.ymin) ymin = *p.ymin;
  if (p.ymax) ymax = *p.ymax;
  expand(xmin, xmax);
  expand(ymin, ymax);
  if (!p.ymin && !p.ymax && !p.diagonal) { double pad = 0.04 * (ymax - ymin); ymin -= pad; ymax += pad; }
}

// Title above, frame with ticks, x label below, y label turned up at the left.
void draw_chart_frame(VectorPlot& o, const AxisFrame& f, const std::string& title, const std::string& xlabel,
                      const std::string& ylabel, double ox, double oy, double W, double H, int x_ticks) {
  o.text({ox + W / 2, oy + 20}, title, 14, kBlack, TextAnchor::kMiddle);
  draw_frame_outline(o, f, kFrame, 1, rgb_hex(0xffffff));
  AxisTicks t;
  t.x_target = x_ticks;
  draw_axis_ticks(o, f, t);
  if (!xlabel.empty()) o.text({f.x + f.w / 2, oy + H - 14}, xlabel, 12, kText, TextAnchor::kMiddle);
  o.text({ox + 16, f.y + f.h / 2}, ylabel, 12, kText, TextAnchor::kMiddle, -90);
}

// The series and bands inside the frame (clipped), zero line and diagonal under them.
void draw_series(VectorPlot& o, const Plot& p, const AxisFrame& f) {
  o.clip(f.clip());
  if (p.zero_line && f.y0 < 0 && f.y1 > 0) o.polyline({f.map(f.x0, 0), f.map(f.x1, 0)}, kLine, 1);
  if (p.diagonal) o.polyline({f.map(f.x0, f.x0), f.map(f.x1, f.x1)}, kLine, 1, true);
  for (auto& b : p.bands) {
    std::vector<Point2> pts;
    for (size_t i = 0; i < b.x.size(); ++i) pts.push_back(f.map(b.x[i], b.hi[i]));
    for (size_t i = b.x.size(); i-- > 0;) pts.push_back(f.map(b.x[i], b.lo[i]));
    o.polygon(pts, with_alpha(b.color, b.opacity));
  }
  for (auto& s : p.series) {
    Rgba c = with_alpha(s.color, s.opacity);
    if (s.line) {  // NaN points break the line into pieces
      std::vector<Point2> piece;
      for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
          piece.push_back(f.map(s.x[i], s.y[i]));
          continue;
        }
        o.polyline(piece, c, s.width, s.dashed);
        piece.clear();
      }
      o.polyline(piece, c, s.width, s.dashed);
    }
    if (s.markers)
      for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) o.circle(f.map(s.x[i], s.y[i]), 3, c);
  }
  o.clip({});
}

// Legend of the labelled bands and series: top right inside the frame, or top left on
// predicted-vs-measured plots whose points fill that corner.
void draw_legend(VectorPlot& o, const Plot& p, const AxisFrame& f) {
  int row = 0;
  auto entry = [&](const std::string& label, const Rgba& color, bool band, bool dashed) {
    double lx = p.diagonal ? f.x + 10 : f.x + f.w - 190, ly = f.y + 14 + 16 * row++;
    o.rect(lx - 4, ly - 11, 190, 16, rgb_hex(0xffffff, 0.8f));
    if (band) o.rect(lx, ly - 8, 22, 10, with_alpha(color, 0.35));
    else o.polyline({{lx, ly - 4}, {lx + 22, ly - 4}}, with_alpha(color, 1), 2, dashed);
    o.text({lx + 28, ly}, label, 12, kText);
  };
  for (auto& b : p.bands)
    if (!b.label.empty()) entry(b.label, b.color, true, false);
  for (auto& s : p.series)
    if (!s.label.empty()) entry(s.label, s.color, false, s.dashed);
}

// One plot inside the box (ox, oy, W, H) of the picture.
void draw_plot(VectorPlot& o, const Plot& p, double ox, double oy, double W, double H) {
  AxisFrame f{ox + 70, oy + 34, W - 90, H - 84, 0, 1, 0, 1};
  data_range(p, f.x0, f.x1, f.y0, f.y1);
  draw_chart_frame(o, f, p.title, p.xlabel, p.ylabel, ox, oy, W, H, 6);
  draw_series(o, p, f);
  draw_legend(o, p, f);
}

// The bars' colour: the chart's own for series s, else the palette's.
Rgba bar_color(const BarChart& b, size_t s) { return s < b.colors.size() ? b.colors[s] : palette_color(static_cast<int>(s)); }

// Bars of every series side by side per category, the category's marker across them, the
// category label below turned by -35 degrees.
void draw_bars(VectorPlot& o, const BarChart& b, const AxisFrame& f) {
  size_t nc = b.categories.size(), ns = b.values.size();
  double cw = f.w / std::max<size_t>(1, nc), bw = cw * 0.8 / std::max<size_t>(1, ns);
  for (size_t c = 0; c < nc; ++c) {
    double cx = f.x + c * cw + cw * 0.1;
    for (size_t s = 0; s < ns; ++s) {
      double v = c < b.values[s].size() ? b.values[s][c] : NAN;
      if (!std::isfinite(v)) continue;
      double y1 = f.map(0, std::max(v, 0.0))[1], y2 = f.map(0, std::min(v, 0.0))[1];
      o.rect(cx + s * bw, y1, bw * 0.95, y2 - y1, bar_color(b, s));
    }
    if (c < b.markers.size() && std::isfinite(b.markers[c])) {
      double y = f.map(0, b.markers[c])[1];
      o.polyline({{cx - 2, y}, {cx + cw * 0.8 + 2, y}}, kBlack, 2, true);
    }
    o.text({f.x + c * cw + cw / 2, f.y + f.h + 14}, b.categories[c], 12, kText, TextAnchor::kEnd, -35);
  }
  if (f.y0 < 0) o.polyline({f.map(0, 0), f.map(1, 0)}, kLine, 1);
}

// The series names with their colours, and the marker's meaning, top right inside the frame.
void draw_bar_legend(VectorPlot& o, const BarChart& b, const AxisFrame& f) {
  size_t lname = b.marker_label.size();
  for (auto& n : b.series_names) lname = std::max(lname, n.size());
  const double lw = 30 + 6.5 * static_cast<double>(lname);
  const size_t ns = b.values.size();
  for (size_t s = 0; s < ns; ++s) {
    double lx = f.x + f.w - lw, ly = f.y + 16 + 16 * s;
    o.rect(lx, ly - 9, 12, 10, bar_color(b, s));
    o.text({lx + 18, ly}, s < b.series_names.size() ? b.series_names[s] : "", 12, kText);
  }
  if (!b.marker_label.empty()) {
    double lx = f.x + f.w - lw, ly = f.y + 16 + 16 * ns;
    o.polyline({{lx, ly - 4}, {lx + 12, ly - 4}}, kBlack, 2, true);
    o.text({lx + 18, ly}, b.marker_label, 12, kText);
  }
}

}  // namespace

VectorPlot line_chart(const Plot& p, int w, int h) {
  VectorPlot o(w, h);
  draw_plot(o, p, 0, 0, w, h);
  return o;
}

VectorPlot chart_panels(const std::vector<Plot>& plots, int cols, int pw, int ph, const std::string& title) {
  cols = std::max(1, cols);
  int rows = static_cast<int>((plots.size() + cols - 1) / cols);
  int top = title.empty() ? 0 : 30;
  VectorPlot o(cols * pw, rows * ph + top);
  if (!title.empty()) o.text({cols * pw / 2.0, 20}, title, 16, kBlack, TextAnchor::kMiddle);
  for (size_t k = 0; k < plots.size(); ++k) draw_plot(o, plots[k], double(k % cols) * pw, top + double(k / cols) * ph, pw, ph);
  return o;
}

VectorPlot bar_chart(const BarChart& b, int W, int H) {
  VectorPlot o(W, H);
  double ymax = 0, ymin = 0;
  for (auto& s : b.values)
    for (double v : s)
      if (std::isfinite(v)) { ymax = std::max(ymax, v); ymin = std::min(ymin, v); }
  for (double v : b.markers)
    if (std::isfinite(v)) { ymax = std::max(ymax, v); ymin = std::min(ymin, v); }
  if (!(ymax > ymin)) ymax = ymin + 1;
  ymax += 0.08 * (ymax - ymin);
  // Room below the axis for category labels written at -35 degrees (about 6.5 px per character).
  size_t longest = 0;
  for (auto& c : b.categories) longest = std::max(longest, c.size());
  double below = 24 + 0.57 * 6.5 * static_cast<double>(longest);
  AxisFrame f{70, 34, W - 90.0, std::max(80.0, H - 34 - below), 0, 1, ymin, ymax};
  draw_chart_frame(o, f, b.title, "", b.ylabel, 0, 0, W, H, 0);
  draw_bars(o, b, f);
  draw_bar_legend(o, b, f);
  return o;
}

}  // namespace ofl
