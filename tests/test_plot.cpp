// The plot layer (renderer/plot/): the PNG a drawing list writes has the picture's size and the
// drawn colours where they were drawn, rotated text turns, the SVG holds one element per drawn
// primitive, and a chart maps its data where the frame says.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "renderer/plot/axis_frame.h"
#include "renderer/plot/charts.h"
#include "renderer/plot/palette.h"
#include "renderer/plot/vector_plot.h"
#include "tests/cli_runner.h"

using namespace ofl;
using ofl::test::fresh_dir;
using ofl::test::slurp;

namespace {

struct Decoded {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  std::array<int, 3> at(int x, int y) const {
    size_t i = (size_t(y) * width + x) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

Decoded read_png(const std::filesystem::path& f) {
  auto in = OIIO::ImageInput::open(f.string());
  EXPECT_TRUE(in) << f;
  Decoded d;
  if (!in) return d;
  d.width = in->spec().width;
  d.height = in->spec().height;
  d.rgb.resize(size_t(d.width) * d.height * 3);
  EXPECT_EQ(in->spec().nchannels, 3);
  in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, d.rgb.data());
  return d;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST(Plot, PngHasThePicturesSizeAndTheDrawnColoursWhereTheyWereDrawn) {
  auto dir = fresh_dir("plot_png");
  VectorPlot p(64, 40);
  p.rect(10, 8, 20, 12, rgb_hex(0xd62728));                 // opaque red block: x 10..30, y 8..20
  p.circle({48, 28}, 6, rgb_hex(0x1f77b4, 0.5f));           // half-transparent blue disc over white
  p.polyline({{2, 36}, {62, 36}}, rgb_hex(0x000000), 2.0);  // a black line 2 px thick at y = 36
  p.write_svg_and_png(dir / "shapes");
  Decoded d = read_png(dir / "shapes.png");
  ASSERT_EQ(d.width, 64);
  ASSERT_EQ(d.height, 40);
  EXPECT_EQ(d.at(20, 14), (std::array<int, 3>{0xd6, 0x27, 0x28}));  // inside the block
  EXPECT_EQ(d.at(5, 4), (std::array<int, 3>{255, 255, 255}));       // background
  // 50 % blue over white at the disc's centre: 255 + 0.5 (c - 255) per channel.
  auto c = d.at(48, 28);
  EXPECT_NEAR(c[0], 0.5 * (0x1f + 255), 1.0);
  EXPECT_NEAR(c[1], 0.5 * (0x77 + 255), 1.0);
  EXPECT_NEAR(c[2], 0.5 * (0xb4 + 255), 1.0);
  // The line covers rows 35 and 36 fully (centre 36, half width 1).
  EXPECT_EQ(d.at(30, 35), (std::array<int, 3>{0, 0, 0}));
  EXPECT_EQ(d.at(30, 32), (std::array<int, 3>{255, 255, 255}));
  // The SVG beside it: one element per primitive (the block is a polygon), the picture's size.
  std::string svg = slurp(dir / "shapes.svg");
  EXPECT_EQ(count(svg, "<polygon"), 1u);
  EXPECT_EQ(count(svg, "<circle"), 1u);
  EXPECT_EQ(count(svg, "<polyline"), 1u);
  EXPECT_NE(svg.find("width=\"64\" height=\"40\""), std::string::npos);
}

TEST(Plot, RotatedTextTurnsInThePng) {
  auto dir = fresh_dir("plot_text");
  VectorPlot flat(120, 120), turned(120, 120);
  flat.text({20, 60}, "WWWWWWWW", 14, rgb_hex(0x000000));
  turned.text({60, 100}, "WWWWWWWW", 14, rgb_hex(0x000000), TextAnchor::kStart, -90);
  if (!flat.write_png(dir / "flat.png") || !turned.write_png(dir / "turned.png")) GTEST_SKIP() << "no TrueType font";
  // Bounding box of the inked pixels: wide for flat text, tall for text turned by -90 degrees, and
  // the turned text rises from its anchor (it reads upwards).
  auto box = [](const Decoded& d) {
    int x0 = d.width, x1 = -1, y0 = d.height, y1 = -1;
    for (int y = 0; y < d.height; ++y)
      for (int x = 0; x < d.width; ++x)
        if (d.at(x, y)[0] < 128) {
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
    return std::array<int, 4>{x0, x1, y0, y1};
  };
  auto f = box(read_png(dir / "flat.png")), t = box(read_png(dir / "turned.png"));
  ASSERT_GE(f[1], f[0]);
  ASSERT_GE(t[1], t[0]);
  int fw = f[1] - f[0] + 1, fh = f[3] - f[2] + 1, tw = t[1] - t[0] + 1, th = t[3] - t[2] + 1;
  EXPECT_GT(fw, 3 * fh);
  EXPECT_GT(th, 3 * tw);
  EXPECT_NEAR(th, fw, 3);   // the same text, turned
  EXPECT_LE(t[3], 100);     // above the anchor ...
  EXPECT_GE(t[3], 95);      // ... starting at it
  EXPECT_LE(t[1], 60);      // glyphs stand left of the baseline when it runs upwards
  std::string svg = turned.to_svg();
  EXPECT_NE(svg.find("transform=\"rotate(-90 60 100)\""), std::string::npos);
}

TEST(Plot, ChartPutsItsDataWhereTheFrameMapsIt) {
  auto dir = fresh_dir("plot_chart");
  // One band from y = 0 to y = 1 over x in [0, 10]: with fixed limits the frame maps it exactly.
  Plot pl;
  pl.xmin = 0;
  pl.xmax = 10;
  pl.ymin = -1;
  pl.ymax = 2;
  pl.bands.push_back({{0, 10}, {0, 0}, {1, 1}, rgb_hex(0x2ca02c), 1.0, ""});
  PlotSeries s;
  s.x = {1, 2, 3, 4};
  s.y = {0.5, 1.5, NAN, 0.2};
  s.line = false;
  s.markers = true;
  pl.series.push_back(s);
  VectorPlot v = line_chart(pl, 400, 300);
  v.write_svg_and_png(dir / "chart");
  Decoded d = read_png(dir / "chart.png");
  ASSERT_EQ(d.width, 400);
  ASSERT_EQ(d.height, 300);
  // line_chart's frame: x from 70 to 70 + (400 - 90), y from 34 to 34 + (300 - 84).
  AxisFrame f{70, 34, 310, 216, 0, 10, -1, 2};
  Point2 inside = f.map(7, 0.5), outside = f.map(7, 1.5);
  EXPECT_EQ(d.at(int(inside[0]), int(inside[1])), (std::array<int, 3>{0x2c, 0xa0, 0x2c}));
  auto o = d.at(int(outside[0]), int(outside[1]));
  EXPECT_GT(o[1], 200);  // white (or a light grid line) above the band
  EXPECT_GT(o[0], 200);
  // Three finite points, three markers (the NaN one left out).
  EXPECT_EQ(count(slurp(dir / "chart.svg"), "<circle"), 3u);
}

TEST(Plot, PaletteCyclesTenColours) {
  EXPECT_EQ(palette_color(0).r, rgb_hex(0x1f77b4).r);
  EXPECT_EQ(palette_color(10).b, palette_color(0).b);
  EXPECT_EQ(palette_color(-1).g, palette_color(9).g);
  EXPECT_NE(palette_color(1).r, palette_color(0).r);
}
