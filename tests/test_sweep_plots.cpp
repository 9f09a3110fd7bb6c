// The report's plots: inline SVGs keep their clip paths apart, categorical metric plots put each
// level at its own place, and a zoomed chromaticity scatter whose reference lines run far outside
// the window is drawn (dashes only where the picture is) as SVG and PNG.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <regex>
#include <set>

#include "renderer/sweep/metrics/sweep_plots.h"

using namespace ofl;

namespace {
nlohmann::ordered_json synthetic_point() {
  nlohmann::ordered_json cells = nlohmann::ordered_json::array();
  for (int i = 0; i < 200; ++i) cells.push_back({0.19 + 0.0002 * (i % 20), 0.50 + 0.0003 * (i / 20)});
  nlohmann::ordered_json r;
  r["index"] = 3;
  r["scatter"]["uniform"] = {{"cells_nf", cells},
                             {"mean_nf", {0.192, 0.5015}},
                             {"ellipse_nf", {{"a", 0.004}, {"b", 0.002}, {"angle_rad", 0.3}}}};
  // Lines from the tongue point far below the window to pure fluorophores far outside it.
  r["reference"]["tongue_rg"] = {0.3588, 0.1277};
  r["reference"]["lines"] = {{{"fluorophore", "FAD"}, {"rg", {{0.3588, 0.1277}, {0.30, 0.30}, {0.1911, 0.6152}}}},
                             {{"fluorophore", "protoporphyrin"}, {"rg", {{0.3588, 0.1277}, {0.8029, 0.1424}}}}};
  return r;
}
}  // namespace

TEST(SweepPlots, InlineSvgsHaveTheirOwnClipPaths) {
  VectorPlot p = metric_plot({"a.b", "x", {}, false}, {{0, 1, 0}, {1, 2, 1}});
  std::string s1 = inline_svg(p, "p1_"), s2 = inline_svg(p, "p2_");
  EXPECT_EQ(s1.rfind("<svg class=\"plot\"", 0), 0u);
  std::set<std::string> ids;
  std::regex id("id=\"([^\"]+)\"");
  for (const std::string* s : {&s1, &s2})
    for (auto it = std::sregex_iterator(s->begin(), s->end(), id); it != std::sregex_iterator(); ++it)
      EXPECT_TRUE(ids.insert((*it)[1]).second) << "duplicate id " << (*it)[1];
  EXPECT_FALSE(ids.empty());
  EXPECT_NE(s1.find("url(#p1_c"), std::string::npos);
  EXPECT_EQ(s1.find("url(#c"), std::string::npos);
}

TEST(SweepPlots, CategoricalLevelsSitAtTheirOwnPlaces) {
  // One point per level: the dots lie on the mean line, one per category, left to right.
  MetricPlotSpec spec{"roi.metric", "variant", {"a", "b", "c"}, false};
  VectorPlot p = metric_plot(spec, {{0, 1.0, 0}, {1, 2.0, 1}, {2, 3.0, 2}});
  std::string svg = p.to_svg();
  std::regex circle("<circle cx=\"([-0-9.e+]+)\"");
  std::vector<double> xs;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), circle); it != std::sregex_iterator(); ++it)
    xs.push_back(std::stod((*it)[1]));
  ASSERT_EQ(xs.size(), 3u);
  for (double x : xs) {
    EXPECT_GT(x, 0);
    EXPECT_LT(x, p.width());
  }
  EXPECT_LT(xs[0], xs[1]);
  EXPECT_LT(xs[1], xs[2]);
  EXPECT_NEAR(xs[1] - xs[0], xs[2] - xs[1], 1e-3);  // SVG keeps 6 digits
}

TEST(SweepPlots, ZoomedScatterWithFarReachingLinesRendersToPng) {
  auto pt = synthetic_point();
  ScatterStyle style{{"uniform"}, {1}, true};
  ChromaWindow w = common_chroma_window({&pt}, style);
  EXPECT_LT(w.r1 - w.r0, 0.05);  // zoomed on the cells, far smaller than the reference lines
  VectorPlot p = point_chroma_plot(pt, style, w);
  auto file = std::filesystem::temp_directory_path() / ("ofl_sweep_plot_" + std::to_string(::getpid()) + ".png");
  p.write_png(file);
  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, p.width());
  EXPECT_EQ(in->spec().height, p.height());
  in->close();
  std::filesystem::remove(file);
}

TEST(SweepPlots, DashedLineEndsAtEveryDashBoundary) {
  // Points of a reference line from a real report: stepping along it by recomputing the dash phase
  // with fmod landed a hair short of a dash boundary and advanced by less than one ulp forever.
  std::vector<Point2> pts = {
      {172.376, 285.63},
      {174.726, 285.542},
      {176.526, 285.474},
      {179.655, 285.355},
      {185.019, 285.158},
      {193.963, 284.82},
      {208.23, 284.286},
      {229.428, 283.492},
      {257.847, 282.429},
      {291.107, 281.184},
      {324.366, 279.939},
      {352.791, 278.875},
      {373.989, 278.081},
      {388.25, 277.547},
      {397.199, 277.215},
      {402.559, 277.013},
      {405.692, 276.893},
      {407.487, 276.826}};
  VectorPlot p(320, 300);
  p.polyline(pts, rgb_hex(0xff7f0e), 1.6, true);
  auto file = std::filesystem::temp_directory_path() / ("ofl_sweep_dash_" + std::to_string(::getpid()) + ".png");
  p.write_png(file);
  std::vector<float> px(320 * 300 * 3);
  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data());
  in->close();
  std::filesystem::remove(file);
  // Dashes along the line: pixels on it alternate between ink and background.
  int ink = 0, paper = 0;
  for (int x = 180; x < 300; ++x) {
    int y = int(std::lround(285.5 - (x - 172.4) * 8.8 / 235.1));
    float v = px[(size_t(y) * 320 + x) * 3 + 2];  // blue channel: orange ink is dark in blue
    (v < 0.6f ? ink : paper) += 1;
  }
  EXPECT_GT(ink, 30);
  EXPECT_GT(paper, 20);
}
