#include "renderer/sweep/metrics/sweep_plots.h"

#include "renderer/plot/axis_frame.h"
#include "renderer/plot/palette.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

namespace ofl {
namespace {

// ROIs and reference lines in colours of the one palette (palette.h); the lines, dashed, in
// colours the ROIs do not use.
const int kRoiColors[] = {0, 1, 2, 4, 5, 7};
const int kLineColors[] = {3, 6, 9, 8};

void pad_range(double* lo, double* hi, double frac) {
  if (!(*hi > *lo)) {
    double c = *lo, d = std::max(std::fabs(c) * 0.05, 1e-9);
    *lo = c - d;
    *hi = c + d;
    return;
  }
  double d = (*hi - *lo) * frac;
  *lo -= d;
  *hi += d;
}

// The frame of every sweep plot: ticks (or category labels), outline, title above, x label below.
void draw_frame(VectorPlot& p, const AxisFrame& f, const std::string& title, const std::string& xlabel,
                const std::vector<std::string>& categories = {}) {
  Rgba axis = rgb_hex(0x333333), label = rgb_hex(0x222222);
  AxisTicks t;
  t.x_target = t.y_target = 4;
  t.y_first = true;
  t.font = 10;
  t.x_label_dy = 14;
  t.y_label_dx = 4;
  t.grid = rgb_hex(0xe3e3e3);
  t.categories = categories;
  t.max_category_chars = 16;
  draw_axis_ticks(p, f, t);
  draw_frame_outline(p, f, axis, 1);
  p.text({f.x + f.w / 2, f.y - 8}, title, 12, label, TextAnchor::kMiddle);
  p.text({f.x + f.w / 2, f.y + f.h + 30}, xlabel, 11, label, TextAnchor::kMiddle);
}

}  // namespace

Rgba roi_color(size_t k) { return palette_color(kRoiColors[k % 6]); }
Rgba line_color(size_t k) { return palette_color(kLineColors[k % 4]); }

VectorPlot metric_plot(const MetricPlotSpec& s, const std::vector<MetricSample>& samples, int width, int height) {
  VectorPlot p(width, height);
  AxisFrame f{58, 24, width - 70.0, height - 70.0, 0, 1, 0, 1};
  const bool cat = !s.categories.empty();
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (auto& m : samples) {
    xmin = std::min(xmin, m.x);
    xmax = std::max(xmax, m.x);
    ymin = std::min(ymin, m.y);
    ymax = std::max(ymax, m.y);
  }
  if (samples.empty()) {
    xmin = 0, xmax = 1, ymin = 0, ymax = 1;
  }
  if (cat) {
    xmin = -0.5;
    xmax = double(s.categories.size()) - 0.5;
  } else {
    pad_range(&xmin, &xmax, 0.06);
  }
  pad_range(&ymin, &ymax, 0.08);
  f.x0 = xmin, f.x1 = xmax, f.y0 = ymin, f.y1 = ymax;
  draw_frame(p, f, s.title, s.x_label, s.categories);
  p.clip(f.clip());
  // Mean per level, joined in x order: the trend the other parameters average over.
  std::map<int, std::pair<double, std::pair<double, int>>> by_level;  // level -> (x, (sum y, n))
  for (auto& m : samples)
    if (m.level >= 0) {
      auto& e = by_level[m.level];
      e.first = m.x;
      e.second.first += m.y;
      e.second.second += 1;
    }
  if (cat) {
    // Unordered levels: a short bar at each level's mean, no line between levels.
    for (auto& [l, e] : by_level) {
      double m = e.second.first / e.second.second;
      p.polyline({f.map(e.first - 0.3, m), f.map(e.first + 0.3, m)}, rgb_hex(0xd62728, 0.9f), 1.8);
    }
  } else if (by_level.size() >= 2) {
    std::vector<std::pair<double, double>> mean;
    for (auto& [l, e] : by_level) mean.push_back({e.first, e.second.first / e.second.second});
    std::sort(mean.begin(), mean.end());
    std::vector<Point2> pts;
    for (auto& [x, y] : mean) pts.push_back(f.map(x, y));
    p.polyline(pts, rgb_hex(0xd62728, 0.9f), 1.8);
  }
  // Jitter categorical dots a little so that points at one level do not hide each other.
  bool shared = false;  // several points at one level
  for (auto& [l, e] : by_level) shared = shared || e.second.second > 1;
  for (size_t i = 0; i < samples.size(); ++i) {
    double x = samples[i].x;
    if (cat && shared) x += (int((i * 7919) % 21) - 10) * 0.012;
    p.circle(f.map(x, samples[i].y), 3.2, rgb_hex(0x1f77b4, 0.65f));
  }
  p.clip({});
  if (samples.empty()) p.text({f.x + f.w / 2, f.y + f.h / 2}, "no data", 12, rgb_hex(0x888888), TextAnchor::kMiddle);
  return p;
}

ChromaWindow common_chroma_window(const std::vector<const nlohmann::ordered_json*>& results, const ScatterStyle& style) {
  std::vector<double> r, g;
  const std::string cells = style.noise_free ? "cells_nf" : "cells";
  for (const auto* res : results) {
    if (!res || !res->contains("scatter")) continue;
    for (auto& name : style.rois) {
      if (!(*res)["scatter"].contains(name) || !(*res)["scatter"][name].contains(cells)) continue;
      const auto& s = (*res)["scatter"][name];
      for (auto& c : s[cells]) {
        r.push_back(c[0].get<double>());
        g.push_back(c[1].get<double>());
      }
    }
  }
  ChromaWindow w;
  if (r.empty()) return w;
  std::sort(r.begin(), r.end());
  std::sort(g.begin(), g.end());
  auto q = [](const std::vector<double>& v, double p) { return v[size_t(std::floor(p * double(v.size() - 1)))]; };
  w.r0 = q(r, 0.01), w.r1 = q(r, 0.99), w.g0 = q(g, 0.01), w.g1 = q(g, 0.99);
  // Square in (r, g) units with a margin, at least 0.02 wide.
  double cr = 0.5 * (w.r0 + w.r1), cg = 0.5 * (w.g0 + w.g1);
  double half = std::max({0.01, 0.5 * (w.r1 - w.r0), 0.5 * (w.g1 - w.g0)}) * 1.25;
  return {cr - half, cr + half, cg - half, cg + half};
}

VectorPlot point_chroma_plot(const nlohmann::ordered_json& res, const ScatterStyle& style, const ChromaWindow& win,
                             int width, int height) {
  const std::string sfx = style.noise_free ? "_nf" : "";
  VectorPlot p(width, height);
  double side = std::min(width - 70.0, height - 80.0);
  AxisFrame f{58, 24, side, side, win.r0, win.r1, win.g0, win.g1};
  // "point 4: variant=lp_absorbing (noise-free)", the label left out when it is too long to fit.
  std::string label = res.value("label", std::string());
  std::string title = "point " + std::to_string(res.value("index", -1));
  if (!label.empty() && label.size() <= 30) title += ": " + label;
  if (style.noise_free) title += " (noise-free)";
  draw_frame(p, f, title, "r = R / (R + G + B)");
  p.text({14, f.y + f.h / 2 - 10}, "g", 11, rgb_hex(0x222222), TextAnchor::kMiddle);
  p.clip(f.clip());
  // Reference lines first, under the cells.
  if (res.contains("reference")) {
    const auto& lines = res["reference"]["lines"];
    for (size_t i = 0; i < lines.size(); ++i) {
      std::vector<Point2> pts;
      for (auto& q : lines[i]["rg"]) pts.push_back(f.map(q[0].get<double>(), q[1].get<double>()));
      p.polyline(pts, line_color(i), 1.6, true);
      for (size_t k = 1; k < pts.size(); k += 4) p.circle(pts[k], 2.0, line_color(i));
    }
    const auto& t = res["reference"]["tongue_rg"];
    if (t.is_array()) {
      auto c = f.map(t[0].get<double>(), t[1].get<double>());
      p.rect(c[0] - 4, c[1] - 4, 8, 8, rgb_hex(0x000000));
    }
  }
  for (size_t k = 0; k < style.rois.size(); ++k) {
    if (!res["scatter"].contains(style.rois[k]) || !res["scatter"][style.rois[k]].contains("cells" + sfx)) continue;
    const auto& s = res["scatter"][style.rois[k]];
    Rgba c = roi_color(style.color[k]);
    Rgba dot = c;
    dot.a = 0.45f;
    for (auto& q : s["cells" + sfx]) p.circle(f.map(q[0].get<double>(), q[1].get<double>()), 1.8, dot);
    if (s.contains("ellipse" + sfx)) {
      const auto& e = s["ellipse" + sfx];
      double mr = s["mean" + sfx][0].get<double>(), mg = s["mean" + sfx][1].get<double>();
      p.polygon(ellipse_outline(f, mr, mg, e["a"].get<double>(), e["b"].get<double>(), e["angle_rad"].get<double>(), 64),
                {0, 0, 0, 0}, c, 1.6);
      auto m = f.map(mr, mg);
      p.polyline({{m[0] - 5, m[1]}, {m[0] + 5, m[1]}}, rgb_hex(0x000000), 1.8);
      p.polyline({{m[0], m[1] - 5}, {m[0], m[1] + 5}}, rgb_hex(0x000000), 1.8);
    }
  }
  p.clip({});
  // Legend under the frame: ROIs.
  double lx = f.x, ly = f.y + f.h + 44;
  for (size_t k = 0; k < style.rois.size(); ++k) {
    p.circle({lx + 4, ly - 4}, 4, roi_color(style.color[k]));
    p.text({lx + 11, ly}, style.rois[k], 10, rgb_hex(0x222222));
    lx += 14 + 7.0 * style.rois[k].size();
  }
  return p;
}

std::string inline_svg(const VectorPlot& plot, const std::string& prefix, const std::string& css_class) {
  std::string s = plot.to_svg();
  // <svg ... -> <svg class="..." ...; id="cN" -> id="<prefix>cN"; url(#cN) -> url(#<prefix>cN)
  s.replace(0, 4, "<svg class=\"" + css_class + "\"");
  std::string out;
  out.reserve(s.size() + 64);
  for (size_t i = 0; i < s.size();) {
    if (s.compare(i, 5, "id=\"c") == 0) {
      out += "id=\"" + prefix + "c";
      i += 5;
    } else if (s.compare(i, 6, "url(#c") == 0) {
      out += "url(#" + prefix + "c";
      i += 6;
    } else {
      out += s[i++];
    }
  }
  return out;
}

}  // namespace ofl
