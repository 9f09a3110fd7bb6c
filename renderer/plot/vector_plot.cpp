#include "renderer/plot/vector_plot.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/image_file.h"

namespace ofl {

Rgba rgb_hex(unsigned hex, float alpha) {
  return {((hex >> 16) & 0xff) / 255.0f, ((hex >> 8) & 0xff) / 255.0f, (hex & 0xff) / 255.0f, alpha};
}

VectorPlot::VectorPlot(int w, int h, Rgba bg) : width_(w), height_(h), background_(bg) {}

VectorPlot::Item& VectorPlot::add(Item::Kind kind, std::vector<Point2> pts, Rgba stroke, double width) {
  Item& it = items_.emplace_back();
  it.kind = kind;
  it.pts = std::move(pts);
  it.stroke = stroke;
  it.width = width;
  it.clip = clip_;
  return it;
}

void VectorPlot::polyline(const std::vector<Point2>& pts, Rgba color, double width, bool dashed) {
  if (pts.size() < 2) return;
  add(Item::kPolyline, pts, color, width).dashed = dashed;
}

void VectorPlot::polygon(const std::vector<Point2>& pts, Rgba fill, Rgba stroke, double sw) {
  if (pts.size() < 3) return;
  add(Item::kPolygon, pts, stroke, sw).fill = fill;
}

void VectorPlot::circle(Point2 c, double r, Rgba fill, Rgba stroke, double sw) {
  Item& it = add(Item::kCircle, {c}, stroke, sw);
  it.fill = fill;
  it.radius = r;
}

void VectorPlot::rect(double x, double y, double w, double h, Rgba fill, Rgba stroke, double sw) {
  polygon({{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, fill, stroke, sw);
}

void VectorPlot::text(Point2 at, const std::string& s, double size, Rgba color, TextAnchor anchor, double rotate_deg) {
  Item& it = add(Item::kText, {at}, color, 0.0);
  it.rotate_deg = rotate_deg;
  it.size = size;
  it.text = s;
  it.anchor = anchor;
}

// ---------------------------------------------------------------------------------------------- SVG

std::string svg_escape(const std::string& s) {
  std::string o;
  for (char ch : s) {
    if (ch == '<') o += "&lt;";
    else if (ch == '>') o += "&gt;";
    else if (ch == '&') o += "&amp;";
    else if (ch == '"') o += "&quot;";
    else o += ch;
  }
  return o;
}

namespace {
std::string svg_color(const Rgba& c) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", static_cast<int>(std::lround(c.r * 255)),
                static_cast<int>(std::lround(c.g * 255)), static_cast<int>(std::lround(c.b * 255)));
  return buf;
}
std::string paint(const char* what, const Rgba& c) {
  if (c.a <= 0) return std::string(" ") + what + "=\"none\"";
  std::ostringstream s;
  s << " " << what << "=\"" << svg_color(c) << "\"";
  if (c.a < 1) s << " " << what << "-opacity=\"" << c.a << "\"";
  return s.str();
}
}  // namespace

std::string VectorPlot::to_svg() const {
  std::ostringstream s;
  s.precision(6);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width_ << "\" height=\"" << height_
    << "\" viewBox=\"0 0 " << width_ << " " << height_ << "\" font-family=\"DejaVu Sans, Arial, sans-serif\">\n";
  s << "<rect width=\"100%\" height=\"100%\"" << paint("fill", background_) << "/>\n";
  // One clipPath per distinct clip rectangle.
  std::vector<ClipRect> clips;
  auto clip_id = [&](const ClipRect& c) -> int {
    if (!c.active()) return -1;
    for (size_t i = 0; i < clips.size(); ++i)
      if (clips[i].x0 == c.x0 && clips[i].y0 == c.y0 && clips[i].x1 == c.x1 && clips[i].y1 == c.y1)
        return static_cast<int>(i);
    clips.push_back(c);
    return static_cast<int>(clips.size() - 1);
  };
  for (const auto& it : items_) clip_id(it.clip);
  if (!clips.empty()) {
    s << "<defs>\n";
    for (size_t i = 0; i < clips.size(); ++i)
      s << "<clipPath id=\"c" << i << "\"><rect x=\"" << clips[i].x0 << "\" y=\"" << clips[i].y0 << "\" width=\""
        << clips[i].x1 - clips[i].x0 << "\" height=\"" << clips[i].y1 - clips[i].y0 << "\"/></clipPath>\n";
    s << "</defs>\n";
  }
  for (const auto& it : items_) {
    int cid = clip_id(it.clip);
    std::string clip = cid >= 0 ? " clip-path=\"url(#c" + std::to_string(cid) + ")\"" : "";
    switch (it.kind) {
      case Item::kPolyline:
      case Item::kPolygon: {
        s << (it.kind == Item::kPolyline ? "<polyline" : "<polygon") << " points=\"";
        for (const auto& p : it.pts) s << p[0] << "," << p[1] << " ";
        s << "\"" << paint("fill", it.kind == Item::kPolyline ? Rgba{0, 0, 0, 0} : it.fill)
          << paint("stroke", it.width > 0 ? it.stroke : Rgba{0, 0, 0, 0});
        if (it.width > 0) s << " stroke-width=\"" << it.width << "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"";
        if (it.dashed) s << " stroke-dasharray=\"" << 4 * it.width << "," << 3 * it.width << "\"";
        s << clip << "/>\n";
        break;
      }
      case Item::kCircle:
        s << "<circle cx=\"" << it.pts[0][0] << "\" cy=\"" << it.pts[0][1] << "\" r=\"" << it.radius << "\""
          << paint("fill", it.fill) << paint("stroke", it.width > 0 ? it.stroke : Rgba{0, 0, 0, 0});
        if (it.width > 0) s << " stroke-width=\"" << it.width << "\"";
        s << clip << "/>\n";
        break;
      case Item::kText: {
        const char* anchor = it.anchor == TextAnchor::kStart ? "start" : it.anchor == TextAnchor::kMiddle ? "middle" : "end";
        s << "<text x=\"" << it.pts[0][0] << "\" y=\"" << it.pts[0][1] << "\" font-size=\"" << it.size
          << "\" text-anchor=\"" << anchor << "\"" << paint("fill", it.stroke);
        if (it.rotate_deg != 0)
          s << " transform=\"rotate(" << it.rotate_deg << " " << it.pts[0][0] << " " << it.pts[0][1] << ")\"";
        s << clip << ">" << svg_escape(it.text)
          << "</text>\n";
        break;
      }
    }
  }
  s << "</svg>\n";
  return s.str();
}

void VectorPlot::write_svg(const std::filesystem::path& file) const {
  write_file_atomic(file, to_svg());
}

bool VectorPlot::write_svg_and_png(const std::filesystem::path& stem) const {
  auto svg = stem, png = stem;
  svg += ".svg";
  png += ".png";
  write_svg(svg);
  return write_png(png);
}

// ---------------------------------------------------------------------------------------------- PNG

namespace {

struct Canvas {
  int w, h;
  std::vector<float> rgb;  // linear in display values (sRGB-encoded colours blended directly, as SVG viewers do)
  void blend(int x, int y, const Rgba& c, double coverage, const ClipRect& clip) {
    if (x < 0 || y < 0 || x >= w || y >= h || coverage <= 0) return;
    if (clip.active() && (x + 0.5 < clip.x0 || x + 0.5 > clip.x1 || y + 0.5 < clip.y0 || y + 0.5 > clip.y1)) return;
    float a = static_cast<float>(std::min(1.0, coverage) * c.a);
    float* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
    p[0] += a * (c.r - p[0]);
    p[1] += a * (c.g - p[1]);
    p[2] += a * (c.b - p[2]);
  }
};

double segment_distance(double px, double py, const Point2& a, const Point2& b) {
  double vx = b[0] - a[0], vy = b[1] - a[1];
  double l2 = vx * vx + vy * vy;
  double t = l2 > 0 ? std::clamp(((px - a[0]) * vx + (py - a[1]) * vy) / l2, 0.0, 1.0) : 0.0;
  double dx = px - (a[0] + t * vx), dy = py - (a[1] + t * vy);
  return std::sqrt(dx * dx + dy * dy);
}

// A polyline stroked with round joins: each pixel takes the coverage of its nearest segment, so
// joins are not painted twice.
void stroke(Canvas& cv, const std::vector<Point2>& pts, const Rgba& c, double width, const ClipRect& clip) {
  double half = 0.5 * std::max(width, 0.5);
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (auto& p : pts) {
    x0 = std::min(x0, p[0]); y0 = std::min(y0, p[1]);
    x1 = std::max(x1, p[0]); y1 = std::max(y1, p[1]);
  }
  int ix0 = std::max(0, static_cast<int>(std::floor(x0 - half - 1))), iy0 = std::max(0, static_cast<int>(std::floor(y0 - half - 1)));
  int ix1 = std::min(cv.w - 1, static_cast<int>(std::ceil(x1 + half + 1))), iy1 = std::min(cv.h - 1, static_cast<int>(std::ceil(y1 + half + 1)));
  for (int y = iy0; y <= iy1; ++y)
    for (int x = ix0; x <= ix1; ++x) {
      double px = x + 0.5, py = y + 0.5, d = 1e300;
      for (size_t i = 0; i + 1 < pts.size(); ++i) d = std::min(d, segment_distance(px, py, pts[i], pts[i + 1]));
      cv.blend(x, y, c, std::clamp(half + 0.5 - d, 0.0, 1.0), clip);
    }
}

bool inside_polygon(double x, double y, const std::vector<Point2>& p) {
  bool in = false;
  for (size_t i = 0, j = p.size() - 1; i < p.size(); j = i++) {
    if ((p[i][1] > y) != (p[j][1] > y) && x < (p[j][0] - p[i][0]) * (y - p[i][1]) / (p[j][1] - p[i][1]) + p[i][0])
      in = !in;
  }
  return in;
}

void fill_polygon(Canvas& cv, const std::vector<Point2>& pts, const Rgba& c, const ClipRect& clip) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (auto& p : pts) {
    x0 = std::min(x0, p[0]); y0 = std::min(y0, p[1]);
    x1 = std::max(x1, p[0]); y1 = std::max(y1, p[1]);
  }
  int ix0 = std::max(0, static_cast<int>(std::floor(x0))), iy0 = std::max(0, static_cast<int>(std::floor(y0)));
  int ix1 = std::min(cv.w - 1, static_cast<int>(std::ceil(x1))), iy1 = std::min(cv.h - 1, static_cast<int>(std::ceil(y1)));
  constexpr int kS = 4;  // 4x4 supersamples per pixel
  for (int y = iy0; y <= iy1; ++y)
    for (int x = ix0; x <= ix1; ++x) {
      int hits = 0;
      for (int sy = 0; sy < kS; ++sy)
        for (int sx = 0; sx < kS; ++sx) hits += inside_polygon(x + (sx + 0.5) / kS, y + (sy + 0.5) / kS, pts);
      cv.blend(x, y, c, hits / double(kS * kS), clip);
    }
}

void fill_disc(Canvas& cv, const Point2& c, double r, const Rgba& col, const ClipRect& clip) {
  for (int y = static_cast<int>(std::floor(c[1] - r - 1)); y <= static_cast<int>(std::ceil(c[1] + r + 1)); ++y)
    for (int x = static_cast<int>(std::floor(c[0] - r - 1)); x <= static_cast<int>(std::ceil(c[0] + r + 1)); ++x) {
      double d = std::hypot(x + 0.5 - c[0], y + 0.5 - c[1]);
      cv.blend(x, y, col, std::clamp(r + 0.5 - d, 0.0, 1.0), clip);
    }
}

std::string find_font() {
  const char* env = std::getenv("OFL_FONT");
  if (env && *env && std::filesystem::exists(env)) return env;
  for (const char* f : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "/usr/share/fonts/dejavu/DejaVuSans.ttf",
                        "/usr/share/fonts/TTF/DejaVuSans.ttf", "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
                        "/usr/share/fonts/truetype/freefont/FreeSans.ttf", "/Library/Fonts/Arial.ttf",
                        "C:/Windows/Fonts/arial.ttf"})
    if (std::filesystem::exists(f)) return f;
  return {};
}

}  // namespace

namespace {

// A polyline dashed 4 w on, 3 w off along its length. The dash state is carried along explicitly:
// recomputing it with fmod at every step can land a hair short of a dash boundary and then advance
// by less than one ulp forever.
void stroke_dashed(Canvas& cv, const std::vector<Point2>& pts, const Rgba& color, double width, const ClipRect& clip) {
  const double on = 4 * width, off = 3 * width, period = on + off;
  double pos = 0;  // distance along the polyline where the segment starts
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    Point2 a = pts[i], b = pts[i + 1];
    double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (!(len > 0) || !std::isfinite(len)) continue;
    // Only the part of the segment over the canvas is dashed (Liang-Barsky): a line that runs
    // far off the picture (a zoomed plot) would otherwise cost one dash per 7 w of its length.
    double m = width + 2, lo = 0, hi = len;
    auto clip_axis = [&](double p0, double d, double min_v, double max_v) {
      double dir = d / len;
      if (std::fabs(dir) < 1e-15) {
        if (p0 < min_v || p0 > max_v) hi = -1;
        return;
      }
      double t0 = (min_v - p0) / dir, t1 = (max_v - p0) / dir;
      if (t0 > t1) std::swap(t0, t1);
      lo = std::max(lo, t0);
      hi = std::min(hi, t1);
    };
    clip_axis(a[0], b[0] - a[0], -m, cv.w + m);
    clip_axis(a[1], b[1] - a[1], -m, cv.h + m);
    if (hi > lo) {
      double phase = std::fmod(pos + lo, period);
      bool drawing = phase < on;
      double left = drawing ? on - phase : period - phase;
      for (double t = lo; t < hi;) {
        double step = std::min(left, hi - t);
        if (drawing && step > 0)
          stroke(cv, {{a[0] + (b[0] - a[0]) * t / len, a[1] + (b[1] - a[1]) * t / len},
                      {a[0] + (b[0] - a[0]) * (t + step) / len, a[1] + (b[1] - a[1]) * (t + step) / len}},
                 color, width, clip);
        t += step;
        left -= step;
        if (left <= 1e-9 * period) {  // next dash or gap: a full length, so t always moves on
          drawing = !drawing;
          left = drawing ? on : off;
        }
        if (step <= 0) break;
      }
    }
    pos += len;
  }
}

// A filled and/or outlined polygon.
void draw_polygon(Canvas& cv, const std::vector<Point2>& pts, const Rgba& fill, const Rgba& stroke_color, double width,
                  const ClipRect& clip) {
  if (fill.a > 0) fill_polygon(cv, pts, fill, clip);
  if (width > 0) {
    auto closed = pts;
    closed.push_back(pts.front());
    stroke(cv, closed, stroke_color, width, clip);
  }
}

// A filled and/or outlined circle.
void draw_circle(Canvas& cv, const Point2& c, double radius, const Rgba& fill, const Rgba& stroke_color, double width,
                 const ClipRect& clip) {
  if (fill.a > 0) fill_disc(cv, c, radius, fill, clip);
  if (width > 0) {
    std::vector<Point2> ring;
    for (int k = 0; k <= 48; ++k) {
      double a = 2 * 3.14159265358979 * k / 48;
      ring.push_back({c[0] + radius * std::cos(a), c[1] + radius * std::sin(a)});
    }
    stroke(cv, ring, stroke_color, width, clip);
  }
}

// Rotated text: the glyphs' coverage rendered upright into a buffer of their own, then resampled
// (bilinear) onto the canvas turned by `deg` about the anchor point. False when it failed.
bool draw_rotated_text(Canvas& cv, const Point2& at, const std::string& text, double size, const Rgba& color, TextAnchor anchor,
                       double deg, const std::string& font, const ClipRect& clip) {
  const int px = static_cast<int>(std::lround(size));
  OIIO::ROI ext = OIIO::ImageBufAlgo::text_size(text, px, font);
  if (!ext.defined()) return false;
  const int pad = 2, ox = pad - ext.xbegin, oy = pad - ext.ybegin;  // the baseline origin in the buffer
  const int bw = ext.width() + 2 * pad, bh = ext.height() + 2 * pad;
  OIIO::ImageBuf glyphs(OIIO::ImageSpec(bw, bh, 1, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::zero(glyphs);
  const float one[1] = {1.0f};
  if (!OIIO::ImageBufAlgo::render_text(glyphs, ox, oy, text, px, font, one)) return false;
  std::vector<float> cov(static_cast<size_t>(bw) * bh);
  glyphs.get_pixels(OIIO::ROI(0, bw, 0, bh, 0, 1, 0, 1), OIIO::TypeDesc::FLOAT, cov.data());
  // The anchor along the baseline, in buffer coordinates.
  double ax = ox + (anchor == TextAnchor::kStart ? ext.xbegin : anchor == TextAnchor::kMiddle ? 0.5 * (ext.xbegin + ext.xend) : ext.xend);
  double ay = oy;
  const double t = deg * 3.14159265358979323846 / 180.0, c = std::cos(t), s = std::sin(t);
  // Canvas bounding box of the turned buffer.
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (double u : {0.0, double(bw)})
    for (double v : {0.0, double(bh)}) {
      double dx = u - ax, dy = v - ay;
      double X = at[0] + dx * c - dy * s, Y = at[1] + dx * s + dy * c;
      x0 = std::min(x0, X); x1 = std::max(x1, X);
      y0 = std::min(y0, Y); y1 = std::max(y1, Y);
    }
  auto sample = [&](double u, double v) {  // bilinear, zero outside
    int iu = static_cast<int>(std::floor(u - 0.5)), iv = static_cast<int>(std::floor(v - 0.5));
    double fu = u - 0.5 - iu, fv = v - 0.5 - iv, acc = 0;
    for (int k = 0; k < 4; ++k) {
      int uu = iu + (k & 1), vv = iv + (k >> 1);
      if (uu < 0 || vv < 0 || uu >= bw || vv >= bh) continue;
      acc += cov[static_cast<size_t>(vv) * bw + uu] * ((k & 1) ? fu : 1 - fu) * ((k >> 1) ? fv : 1 - fv);
    }
    return acc;
  };
  for (int y = std::max(0, static_cast<int>(std::floor(y0))); y <= std::min(cv.h - 1, static_cast<int>(std::ceil(y1))); ++y)
    for (int x = std::max(0, static_cast<int>(std::floor(x0))); x <= std::min(cv.w - 1, static_cast<int>(std::ceil(x1))); ++x) {
      double dx = x + 0.5 - at[0], dy = y + 0.5 - at[1];
      double u = ax + dx * c + dy * s, v = ay - dx * s + dy * c;  // the inverse turn
      cv.blend(x, y, color, sample(u, v), clip);
    }
  return true;
}

}  // namespace

bool VectorPlot::write_png(const std::filesystem::path& file) const {
  Canvas cv{width_, height_, std::vector<float>(static_cast<size_t>(width_) * height_ * 3)};
  for (size_t i = 0; i < cv.rgb.size(); i += 3) {
    cv.rgb[i] = background_.r;
    cv.rgb[i + 1] = background_.g;
    cv.rgb[i + 2] = background_.b;
  }
  std::string font = find_font();
  bool text_ok = true;
  // Text is drawn after the shapes that precede it, so draw in order, switching to OIIO for text.
  OIIO::ImageSpec spec(width_, height_, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf buf(spec);
  bool buf_current = false;
  auto to_buf = [&] {
    buf.set_pixels(OIIO::ROI(0, width_, 0, height_, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, cv.rgb.data());
    buf_current = true;
  };
  auto from_buf = [&] {
    buf.get_pixels(OIIO::ROI(0, width_, 0, height_, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, cv.rgb.data());
    buf_current = false;
  };
  for (const auto& it : items_) {
    if (it.kind == Item::kText && font.empty()) {
      text_ok = false;
      continue;
    }
    if (it.kind == Item::kText && it.rotate_deg == 0) {
      if (!buf_current) to_buf();
      float col[3] = {it.stroke.r, it.stroke.g, it.stroke.b};
      auto ax = it.anchor == TextAnchor::kStart ? OIIO::ImageBufAlgo::TextAlignX::Left
                : it.anchor == TextAnchor::kMiddle ? OIIO::ImageBufAlgo::TextAlignX::Center
                                                   : OIIO::ImageBufAlgo::TextAlignX::Right;
      if (!OIIO::ImageBufAlgo::render_text(buf, static_cast<int>(std::lround(it.pts[0][0])),
                                           static_cast<int>(std::lround(it.pts[0][1])), it.text,
                                           static_cast<int>(std::lround(it.size * 1.0)), font, col, ax,
                                           OIIO::ImageBufAlgo::TextAlignY::Baseline))
        text_ok = false;
      continue;
    }
    if (buf_current) from_buf();
    switch (it.kind) {
      case Item::kPolyline:
        if (it.dashed) stroke_dashed(cv, it.pts, it.stroke, it.width, it.clip);
        else stroke(cv, it.pts, it.stroke, it.width, it.clip);
        break;
      case Item::kPolygon: draw_polygon(cv, it.pts, it.fill, it.stroke, it.width, it.clip); break;
      case Item::kCircle: draw_circle(cv, it.pts[0], it.radius, it.fill, it.stroke, it.width, it.clip); break;
      case Item::kText:
        if (!draw_rotated_text(cv, it.pts[0], it.text, it.size, it.stroke, it.anchor, it.rotate_deg, font, it.clip)) text_ok = false;
        break;
    }
  }
  if (buf_current) from_buf();
  std::vector<unsigned char> px(cv.rgb.size());
  for (size_t i = 0; i < px.size(); ++i)
    px[i] = static_cast<unsigned char>(std::lround(255.0 * std::clamp(cv.rgb[i], 0.0f, 1.0f)));
  write_image_file(file, OIIO::ImageSpec(width_, height_, 3, OIIO::TypeDesc::UINT8), px.data());
  return text_ok;
}

}  // namespace ofl
