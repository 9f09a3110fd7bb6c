#include "renderer/diagnose/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "renderer/analysis/plot_axis.h"
#include "renderer/analysis/vector_plot.h"

namespace ofl {

namespace {

std::string esc(const std::string& s) { return svg_escape(s); }

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

struct Frame {
  double x0, y0, w, h;  // plotting area in SVG units
  double xmin, xmax, ymin, ymax;
  double X(double x) const { return x0 + (x - xmin) / (xmax - xmin) * w; }
  double Y(double y) const { return y0 + h - (y - ymin) / (ymax - ymin) * h; }
};

void expand(double& lo, double& hi) {
  if (!(hi > lo)) {
    double c = std::isfinite(lo) ? lo : 0;
    lo = c - 1;
    hi = c + 1;
  }
}

// Draws one plot into `o` inside the box (ox, oy, W, H).
void draw_plot(std::ostringstream& o, const Plot& p, double ox, double oy, double W, double H) {
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
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
  Frame f{ox + 70, oy + 34, W - 90, H - 84, xmin, xmax, ymin, ymax};
  o << "<g font-family=\"sans-serif\" font-size=\"12\">\n";
  o << "<text x=\"" << num(ox + W / 2) << "\" y=\"" << num(oy + 20) << "\" text-anchor=\"middle\" font-size=\"14\">" << esc(p.title) << "</text>\n";
  o << "<rect x=\"" << num(f.x0) << "\" y=\"" << num(f.y0) << "\" width=\"" << num(f.w) << "\" height=\"" << num(f.h)
    << "\" fill=\"white\" stroke=\"#444\"/>\n";
  double xs = nice_tick_step(xmax - xmin, 6), ys = nice_tick_step(ymax - ymin, 5);
  for (double t : axis_ticks(xmin, xmax, xs)) {
    o << "<line x1=\"" << num(f.X(t)) << "\" y1=\"" << num(f.y0) << "\" x2=\"" << num(f.X(t)) << "\" y2=\"" << num(f.y0 + f.h)
      << "\" stroke=\"#e4e4e4\"/>\n";
    o << "<text x=\"" << num(f.X(t)) << "\" y=\"" << num(f.y0 + f.h + 16) << "\" text-anchor=\"middle\">" << tick_label(t, xs) << "</text>\n";
  }
  for (double t : axis_ticks(ymin, ymax, ys)) {
    o << "<line x1=\"" << num(f.x0) << "\" y1=\"" << num(f.Y(t)) << "\" x2=\"" << num(f.x0 + f.w) << "\" y2=\"" << num(f.Y(t))
      << "\" stroke=\"#e4e4e4\"/>\n";
    o << "<text x=\"" << num(f.x0 - 6) << "\" y=\"" << num(f.Y(t) + 4) << "\" text-anchor=\"end\">" << tick_label(t, ys) << "</text>\n";
  }
  o << "<text x=\"" << num(f.x0 + f.w / 2) << "\" y=\"" << num(oy + H - 14) << "\" text-anchor=\"middle\">" << esc(p.xlabel) << "</text>\n";
  o << "<text transform=\"translate(" << num(ox + 16) << "," << num(f.y0 + f.h / 2) << ") rotate(-90)\" text-anchor=\"middle\">"
    << esc(p.ylabel) << "</text>\n";
  std::string clip = "c" + std::to_string(static_cast<long>(ox * 7 + oy * 13 + W));
  o << "<clipPath id=\"" << clip << "\"><rect x=\"" << num(f.x0) << "\" y=\"" << num(f.y0) << "\" width=\"" << num(f.w)
    << "\" height=\"" << num(f.h) << "\"/></clipPath>\n<g clip-path=\"url(#" << clip << ")\">\n";
  if (p.zero_line && ymin < 0 && ymax > 0)
    o << "<line x1=\"" << num(f.x0) << "\" y1=\"" << num(f.Y(0)) << "\" x2=\"" << num(f.x0 + f.w) << "\" y2=\"" << num(f.Y(0))
      << "\" stroke=\"#555\" stroke-width=\"1\"/>\n";
  if (p.diagonal)
    o << "<line x1=\"" << num(f.X(xmin)) << "\" y1=\"" << num(f.Y(xmin)) << "\" x2=\"" << num(f.X(xmax)) << "\" y2=\"" << num(f.Y(xmax))
      << "\" stroke=\"#555\" stroke-dasharray=\"4 3\"/>\n";
  for (auto& b : p.bands) {
    std::string pts;
    for (size_t i = 0; i < b.x.size(); ++i) pts += num(f.X(b.x[i])) + "," + num(f.Y(b.hi[i])) + " ";
    for (size_t i = b.x.size(); i-- > 0;) pts += num(f.X(b.x[i])) + "," + num(f.Y(b.lo[i])) + " ";
    o << "<polygon points=\"" << pts << "\" fill=\"" << b.color << "\" fill-opacity=\"" << b.opacity << "\" stroke=\"none\"/>\n";
  }
  for (auto& s : p.series) {
    if (s.line) {
      std::string d;
      bool pen = false;
      for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) { pen = false; continue; }
        d += (pen ? "L" : "M") + num(f.X(s.x[i])) + "," + num(f.Y(s.y[i])) + " ";
        pen = true;
      }
      o << "<path d=\"" << d << "\" fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"" << s.width << "\" stroke-opacity=\""
        << s.opacity << "\"" << (s.dashed ? " stroke-dasharray=\"6 4\"" : "") << "/>\n";
    }
    if (s.markers)
      for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]))
          o << "<circle cx=\"" << num(f.X(s.x[i])) << "\" cy=\"" << num(f.Y(s.y[i])) << "\" r=\"3\" fill=\"" << s.color
            << "\" fill-opacity=\"" << s.opacity << "\"/>\n";
  }
  o << "</g>\n";
  // Legend: labelled series and bands, top-right inside the frame.
  int row = 0;
  auto entry = [&](const std::string& label, const std::string& color, bool band, bool dashed) {
    // Top right, except on predicted-vs-measured plots whose points fill that corner.
    double lx = p.diagonal ? f.x0 + 10 : f.x0 + f.w - 190, ly = f.y0 + 14 + 16 * row++;
    o << "<rect x=\"" << num(lx - 4) << "\" y=\"" << num(ly - 11) << "\" width=\"190\" height=\"16\" fill=\"white\" fill-opacity=\"0.8\"/>\n";
    if (band)
      o << "<rect x=\"" << num(lx) << "\" y=\"" << num(ly - 8) << "\" width=\"22\" height=\"10\" fill=\"" << color << "\" fill-opacity=\"0.35\"/>\n";
    else
      o << "<line x1=\"" << num(lx) << "\" y1=\"" << num(ly - 4) << "\" x2=\"" << num(lx + 22) << "\" y2=\"" << num(ly - 4) << "\" stroke=\""
        << color << "\" stroke-width=\"2\"" << (dashed ? " stroke-dasharray=\"6 4\"" : "") << "/>\n";
    o << "<text x=\"" << num(lx + 28) << "\" y=\"" << num(ly) << "\">" << esc(label) << "</text>\n";
  };
  for (auto& b : p.bands)
    if (!b.label.empty()) entry(b.label, b.color, true, false);
  for (auto& s : p.series)
    if (!s.label.empty()) entry(s.label, s.color, false, s.dashed);
  o << "</g>\n";
}

}  // namespace

std::string palette(int i) {
  static const char* c[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  return c[((i % 10) + 10) % 10];
}

std::string svg_plot(const Plot& p, double w, double h) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h << "\" viewBox=\"0 0 " << w << " " << h << "\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  draw_plot(o, p, 0, 0, w, h);
  o << "</svg>\n";
  return o.str();
}

std::string svg_panels(const std::vector<Plot>& plots, int cols, double pw, double ph, const std::string& title) {
  cols = std::max(1, cols);
  int rows = static_cast<int>((plots.size() + cols - 1) / cols);
  double top = title.empty() ? 0 : 30;
  double w = cols * pw, h = rows * ph + top;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h << "\" viewBox=\"0 0 " << w << " " << h << "\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  if (!title.empty())
    o << "<text x=\"" << num(w / 2) << "\" y=\"20\" text-anchor=\"middle\" font-family=\"sans-serif\" font-size=\"16\" font-weight=\"bold\">"
      << esc(title) << "</text>\n";
  for (size_t k = 0; k < plots.size(); ++k)
    draw_plot(o, plots[k], (k % cols) * pw, top + (k / cols) * ph, pw, ph);
  o << "</svg>\n";
  return o.str();
}

std::string svg_bars(const BarChart& b, double W, double H) {
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H << "\" viewBox=\"0 0 " << W << " " << H << "\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<g font-family=\"sans-serif\" font-size=\"12\">\n";
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
  Frame f{70, 34, W - 90, std::max(80.0, H - 34 - below), 0, 1, ymin, ymax};
  o << "<text x=\"" << num(W / 2) << "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" << esc(b.title) << "</text>\n";
  o << "<rect x=\"" << num(f.x0) << "\" y=\"" << num(f.y0) << "\" width=\"" << num(f.w) << "\" height=\"" << num(f.h)
    << "\" fill=\"white\" stroke=\"#444\"/>\n";
  double ys = nice_tick_step(ymax - ymin, 5);
  for (double t : axis_ticks(ymin, ymax, ys)) {
    o << "<line x1=\"" << num(f.x0) << "\" y1=\"" << num(f.Y(t)) << "\" x2=\"" << num(f.x0 + f.w) << "\" y2=\"" << num(f.Y(t))
      << "\" stroke=\"#e4e4e4\"/>\n";
    o << "<text x=\"" << num(f.x0 - 6) << "\" y=\"" << num(f.Y(t) + 4) << "\" text-anchor=\"end\">" << tick_label(t, ys) << "</text>\n";
  }
  o << "<text transform=\"translate(16," << num(f.y0 + f.h / 2) << ") rotate(-90)\" text-anchor=\"middle\">" << esc(b.ylabel) << "</text>\n";
  size_t nc = b.categories.size(), ns = b.values.size();
  double cw = f.w / std::max<size_t>(1, nc), bw = cw * 0.8 / std::max<size_t>(1, ns);
  for (size_t c = 0; c < nc; ++c) {
    double cx = f.x0 + c * cw + cw * 0.1;
    for (size_t s = 0; s < ns; ++s) {
      double v = c < b.values[s].size() ? b.values[s][c] : NAN;
      if (!std::isfinite(v)) continue;
      double y1 = f.Y(std::max(v, 0.0)), y2 = f.Y(std::min(v, 0.0));
      std::string col = s < b.colors.size() ? b.colors[s] : palette(static_cast<int>(s));
      o << "<rect x=\"" << num(cx + s * bw) << "\" y=\"" << num(y1) << "\" width=\"" << num(bw * 0.95) << "\" height=\"" << num(y2 - y1)
        << "\" fill=\"" << col << "\"/>\n";
    }
    if (c < b.markers.size() && std::isfinite(b.markers[c]))
      o << "<line x1=\"" << num(cx - 2) << "\" y1=\"" << num(f.Y(b.markers[c])) << "\" x2=\"" << num(cx + cw * 0.8 + 2) << "\" y2=\""
        << num(f.Y(b.markers[c])) << "\" stroke=\"black\" stroke-width=\"2\" stroke-dasharray=\"4 2\"/>\n";
    double tx = f.x0 + c * cw + cw / 2, ty = f.y0 + f.h + 14;
    o << "<text transform=\"translate(" << num(tx) << "," << num(ty) << ") rotate(-35)\" text-anchor=\"end\">" << esc(b.categories[c]) << "</text>\n";
  }
  if (ymin < 0)
    o << "<line x1=\"" << num(f.x0) << "\" y1=\"" << num(f.Y(0)) << "\" x2=\"" << num(f.x0 + f.w) << "\" y2=\"" << num(f.Y(0)) << "\" stroke=\"#555\"/>\n";
  size_t lname = b.marker_label.size();
  for (auto& n : b.series_names) lname = std::max(lname, n.size());
  const double lw = 30 + 6.5 * static_cast<double>(lname);
  for (size_t s = 0; s < ns; ++s) {
    double lx = f.x0 + f.w - lw, ly = f.y0 + 16 + 16 * s;
    std::string col = s < b.colors.size() ? b.colors[s] : palette(static_cast<int>(s));
    o << "<rect x=\"" << num(lx) << "\" y=\"" << num(ly - 9) << "\" width=\"12\" height=\"10\" fill=\"" << col << "\"/>\n";
    o << "<text x=\"" << num(lx + 18) << "\" y=\"" << num(ly) << "\">" << esc(s < b.series_names.size() ? b.series_names[s] : "") << "</text>\n";
  }
  if (!b.marker_label.empty()) {
    double lx = f.x0 + f.w - lw, ly = f.y0 + 16 + 16 * ns;
    o << "<line x1=\"" << num(lx) << "\" y1=\"" << num(ly - 4) << "\" x2=\"" << num(lx + 12) << "\" y2=\"" << num(ly - 4)
      << "\" stroke=\"black\" stroke-width=\"2\" stroke-dasharray=\"4 2\"/>\n";
    o << "<text x=\"" << num(lx + 18) << "\" y=\"" << num(ly) << "\">" << esc(b.marker_label) << "</text>\n";
  }
  o << "</g>\n</svg>\n";
  return o.str();
}

}  // namespace ofl
