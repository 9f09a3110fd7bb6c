// The drawing list every plot of the project is made of (docs/architecture.md, "Layers": plot),
// written both as SVG (exact, scalable) and as PNG (our own anti-aliased rasteriser for lines,
// polygons and discs; text through OpenImageIO's FreeType renderer with a system TrueType font
// such as DejaVu Sans, left out with a note when none is found). Coordinates are pixels, origin
// top-left, y down.
#pragma once
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

// Escapes <, >, & and " for SVG and HTML text and attributes (used by every report writer).
std::string svg_escape(const std::string& s);

struct Rgba {
  float r = 0, g = 0, b = 0, a = 1;
};
Rgba rgb_hex(unsigned hex, float alpha = 1.0f);

using Point2 = std::array<double, 2>;

struct ClipRect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // empty (x1 <= x0) means no clipping
  bool active() const { return x1 > x0 && y1 > y0; }
};

enum class TextAnchor { kStart, kMiddle, kEnd };

class VectorPlot {
 public:
  VectorPlot(int width, int height, Rgba background = {1, 1, 1, 1});
  int width() const { return width_; }
  int height() const { return height_; }

  // Later primitives are clipped to `r` until clip() is called with an empty rectangle.
  void clip(const ClipRect& r) { clip_ = r; }
  void polyline(const std::vector<Point2>& pts, Rgba color, double width, bool dashed = false);
  void polygon(const std::vector<Point2>& pts, Rgba fill, Rgba stroke = {0, 0, 0, 0}, double stroke_width = 0);
  void circle(Point2 c, double radius, Rgba fill, Rgba stroke = {0, 0, 0, 0}, double stroke_width = 0);
  void rect(double x, double y, double w, double h, Rgba fill, Rgba stroke = {0, 0, 0, 0}, double stroke_width = 0);
  // Text on its baseline at `at`; `rotate_deg` turns it about `at`, clockwise on the picture as in
  // SVG (-90: read upwards).
  void text(Point2 at, const std::string& s, double size, Rgba color, TextAnchor anchor = TextAnchor::kStart,
            double rotate_deg = 0);

  std::string to_svg() const;
  void write_svg(const std::filesystem::path& file) const;
  // Returns false (and leaves the labels out) when no font was found for the text.
  bool write_png(const std::filesystem::path& file) const;
  // <stem>.svg and <stem>.png; returns write_png's answer.
  bool write_svg_and_png(const std::filesystem::path& stem) const;

 private:
  struct Item {
    enum Kind { kPolyline, kPolygon, kCircle, kText } kind = kPolyline;
    std::vector<Point2> pts;
    Rgba stroke, fill;
    double width = 0, radius = 0, size = 0, rotate_deg = 0;
    bool dashed = false;
    std::string text;
    TextAnchor anchor = TextAnchor::kStart;
    ClipRect clip;
  };
  // A new item of the drawing list with the current clip.
  Item& add(Item::Kind kind, std::vector<Point2> pts, Rgba stroke, double width);
  int width_, height_;
  Rgba background_;
  ClipRect clip_;
  std::vector<Item> items_;
};

}  // namespace ofl
