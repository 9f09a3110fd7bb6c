#include "renderer/analysis/chroma_plot.h"

#include "renderer/plot/axis_frame.h"
#include "renderer/plot/palette.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ofl {
namespace {

struct Box {
  double r0, r1, g0, g1;
};

// Maps (r, g) into a panel of the image, equal scale on both axes (x: r, y: g).
AxisFrame panel(double x, double y, double w, double h, const Box& b) { return {x, y, w, h, b.r0, b.r1, b.g0, b.g1}; }

// Grows `b` to the aspect ratio of a w x h panel around its centre, with a margin.
Box fit_box(Box b, double w, double h, double margin) {
  double dr = std::max(b.r1 - b.r0, 1e-4), dg = std::max(b.g1 - b.g0, 1e-4);
  double cr = 0.5 * (b.r0 + b.r1), cg = 0.5 * (b.g0 + b.g1);
  dr *= 1 + 2 * margin;
  dg *= 1 + 2 * margin;
  if (dr / dg > w / h) dg = dr * h / w;
  else dr = dg * w / h;
  return {cr - dr / 2, cr + dr / 2, cg - dg / 2, cg + dg / 2};
}

void draw_axes(VectorPlot& p, const AxisFrame& pn, const std::string& title) {
  Rgba axis = rgb_hex(0x333333), label = rgb_hex(0x222222);
  AxisTicks t;
  t.shared_step = true;
  t.grid = rgb_hex(0xdddddd);
  draw_axis_ticks(p, pn, t);
  // r + g = 1 (no blue) bounds the possible chromaticities.
  p.clip(pn.clip());
  p.polyline({pn.map(-1, 2), pn.map(2, -1)}, rgb_hex(0x999999), 1, true);
  p.clip({});
  draw_frame_outline(p, pn, axis, 1.2);
  p.text({pn.x + pn.w / 2, pn.y + pn.h + 36}, "r = R / (R + G + B)", 14, label, TextAnchor::kMiddle);
  p.text({pn.x - 48, pn.y - 10}, "g = G / (R + G + B)", 14, label, TextAnchor::kStart);
  p.text({pn.x + pn.w / 2, pn.y - 10}, title, 15, label, TextAnchor::kMiddle);
}

void draw_points(VectorPlot& p, const AxisFrame& pn, const ChromaStats& s, double radius, size_t max_points) {
  p.clip(pn.clip());
  size_t stride = std::max<size_t>(1, s.rg.size() / max_points);
  for (size_t i = 0; i < s.rg.size(); i += stride)
    p.circle(pn.map(s.rg[i][0], s.rg[i][1]), radius, rgb_hex(0x555555, 0.35f));
  if (s.used > 1) p.polygon(ellipse_outline(pn, s.ellipse95.cx, s.ellipse95.cy, s.ellipse95.a, s.ellipse95.b, s.ellipse95.angle_rad, 96), {0, 0, 0, 0},
                             rgb_hex(0x000000), 2.0);
  if (s.used > 0) {
    auto m = pn.map(s.mean_r, s.mean_g);
    p.polyline({{m[0] - 7, m[1]}, {m[0] + 7, m[1]}}, rgb_hex(0x000000), 2.2);
    p.polyline({{m[0], m[1] - 7}, {m[0], m[1] + 7}}, rgb_hex(0x000000), 2.2);
  }
  p.clip({});
}

void draw_lines(VectorPlot& p, const AxisFrame& pn, const std::vector<ReferenceLine>& lines, bool labels) {
  p.clip(pn.clip());
  struct Label {
    Point2 end, at;
    Rgba color;
    std::string text;
  };
  std::vector<Label> tags;
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto& l = lines[i];
    if (!l.visible) continue;
    Rgba c = palette_color(static_cast<int>(i));
    std::vector<Point2> pts;
    for (auto& rg : l.rg) pts.push_back(pn.map(rg[0], rg[1]));
    p.polyline(pts, c, 2.0);
    for (size_t k = 1; k < pts.size(); k += 4) p.circle(pts[k], 3.0, c);
    tags.push_back({pts.back(), {pts.back()[0] + 8, pts.back()[1] + 4}, c, l.fluorophore});
  }
  if (labels) {
    // Push labels apart vertically (at least 14 px), with a leader line when one moved.
    std::sort(tags.begin(), tags.end(), [](const Label& a, const Label& b) { return a.at[1] < b.at[1]; });
    for (size_t k = 1; k < tags.size(); ++k)
      if (std::fabs(tags[k].at[0] - tags[k - 1].at[0]) < 90 && tags[k].at[1] - tags[k - 1].at[1] < 14)
        tags[k].at[1] = tags[k - 1].at[1] + 14;
    p.clip({});
    for (auto& t : tags) {
      // Labels that would leave the panel go to the left of the line's end.
      bool left = t.at[0] + 7.5 * t.text.size() > pn.x + pn.w;
      Point2 at = left ? Point2{t.end[0] - 8, t.at[1]} : t.at;
      if (std::fabs(t.at[1] - 4 - t.end[1]) > 3) p.polyline({t.end, {at[0] + (left ? 2 : -2), at[1] - 4}}, t.color, 0.8);
      p.text(at, t.text, 12, t.color, left ? TextAnchor::kEnd : TextAnchor::kStart);
    }
  }
  if (!lines.empty()) {
    auto t = pn.map(lines[0].rg[0][0], lines[0].rg[0][1]);
    p.rect(t[0] - 5, t[1] - 5, 10, 10, rgb_hex(0x000000));
  }
  p.clip({});
}

}  // namespace

VectorPlot make_chroma_plot(const ChromaPlotData& d, int width, int height) {
  VectorPlot p(width, height);
  const ChromaStats& s = d.stats;
  double top = 86, bottom = 60, left = 70, gap = 90, legend_w = 230, right = 10;
  double pw = (width - left - gap - 24 - legend_w - right) / 2.0, ph = height - top - bottom;

  // Overview box: reference lines, tongue point and ROI mean.
  Box all{1e300, -1e300, 1e300, -1e300};
  auto grow = [](Box& b, double r, double g) {
    if (!std::isfinite(r) || !std::isfinite(g)) return;
    b.r0 = std::min(b.r0, r); b.r1 = std::max(b.r1, r);
    b.g0 = std::min(b.g0, g); b.g1 = std::max(b.g1, g);
  };
  for (const auto& l : d.lines)
    for (const auto& rg : l.rg) grow(all, rg[0], rg[1]);
  // ROI: the central 98 % of its cells and the ellipse.
  Box roi{1e300, -1e300, 1e300, -1e300};
  if (s.used > 0) {
    std::vector<double> rs, gs;
    for (auto& q : s.rg) { rs.push_back(q[0]); gs.push_back(q[1]); }
    std::sort(rs.begin(), rs.end());
    std::sort(gs.begin(), gs.end());
    size_t lo = rs.size() / 100, hi = rs.size() - 1 - rs.size() / 100;
    grow(roi, rs[lo], gs[lo]);
    grow(roi, rs[hi], gs[hi]);
    double ext = std::max(s.ellipse95.a, 1e-4);
    grow(roi, s.mean_r - ext, s.mean_g - ext);
    grow(roi, s.mean_r + ext, s.mean_g + ext);
    grow(all, roi.r0, roi.g0);
    grow(all, roi.r1, roi.g1);
  }
  if (all.r0 > all.r1) all = {0, 1, 0, 1};
  if (roi.r0 > roi.r1) roi = all;
  AxisFrame overview = panel(left, top, pw, ph, fit_box(all, pw, ph, 0.08));
  AxisFrame zoom = panel(left + pw + gap, top, pw, ph, fit_box(roi, pw, ph, 0.15));

  p.text({left, 28}, d.title, 17, rgb_hex(0x000000));
  p.text({left, 50}, d.subtitle, 13, rgb_hex(0x333333));
  draw_axes(p, overview, "overview: reference lines and ROI");
  draw_lines(p, overview, d.lines, true);
  draw_points(p, overview, s, 1.2, 3000);
  draw_axes(p, zoom, "ROI zoom: cells, mean, 95 % ellipse");
  draw_lines(p, zoom, d.lines, false);
  draw_points(p, zoom, s, 1.8, 6000);
  // Zoom window outline on the overview.
  auto a = overview.map(zoom.x0, zoom.y0), b = overview.map(zoom.x1, zoom.y1);
  p.clip(overview.clip());
  p.rect(a[0], b[1], b[0] - a[0], a[1] - b[1], {0, 0, 0, 0}, rgb_hex(0x444444), 1.0);
  p.clip({});

  // Legend to the right of the zoom panel.
  double lx = zoom.x + zoom.w + 24, ly = overview.y;
  int n = 0;
  for (const auto& l : d.lines) n += l.visible;
  double lh = 18.0 * (n + 2) + 8;
  p.rect(lx, ly, legend_w, lh, rgb_hex(0xffffff), rgb_hex(0xaaaaaa), 1);
  double yy = ly + 20;
  p.rect(lx + 10, yy - 9, 10, 10, rgb_hex(0x000000));
  p.text({lx + 28, yy}, "tongue reflectance (c = 0)", 12, rgb_hex(0x000000));
  yy += 18;
  p.circle({lx + 15, yy - 4}, 3, rgb_hex(0x555555, 0.6f));
  p.text({lx + 28, yy}, "ROI cells, + mean, 95 % ellipse", 12, rgb_hex(0x000000));
  for (size_t i = 0; i < d.lines.size(); ++i) {
    if (!d.lines[i].visible) continue;
    yy += 18;
    Rgba c = palette_color(static_cast<int>(i));
    p.polyline({{lx + 8, yy - 4}, {lx + 22, yy - 4}}, c, 2.5);
    p.text({lx + 28, yy}, d.lines[i].fluorophore, 12, c);
  }
  return p;
}

bool write_chroma_plot(const ChromaPlotData& d, const std::filesystem::path& stem) {
  return make_chroma_plot(d).write_svg_and_png(stem);
}

}  // namespace ofl
