// Tongue maps: on the procedural tongue, whose UV layout is known in closed form (u = 0.5 on
// the dorsal midline, u = 0.25 on the left border, v = alpha / pi along the tip-to-back
// parameter with x = a sgn(cos alpha)|cos alpha|^(2/p)), the porphyrin patch must land on the
// dorsal midline at the requested fraction of the length, and the lesion on the left border.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>

#include "renderer/mesh/mouth/procedural_tongue.h"
#include "renderer/mesh/mouth/tongue_maps.h"

using namespace ofl;

namespace {
constexpr double kPi = 3.14159265358979323846;
// v of the ring at `frac` of the length back from the tip.
double v_at_fraction(double frac, double p) {
  double x = 1 - 2 * frac;  // x / a
  double c = std::copysign(std::pow(std::abs(x), p / 2), x);
  return std::acos(c) / kPi;
}
}  // namespace

TEST(MeshTexture, PatchesLandWhereTheSurfaceSays) {
  MouthParams mp;
  mp.segments = 128;
  TriangleMesh tongue = make_procedural_tongue(mp);
  TongueMapParams tp;
  tp.size = 256;
  TongueMaps maps = make_tongue_maps({tongue}, tp);
  const double p = tongue_shape(mp).p;

  auto por = maps.report.at("porphyrin").at("uv_centroid");
  EXPECT_NEAR(por[0].get<double>(), 0.5, 0.01);
  EXPECT_NEAR(por[1].get<double>(), v_at_fraction(tp.porphyrin_center_frac, p), 0.03);
  EXPECT_NEAR(maps.report.at("porphyrin").at("peak").get<double>(), 1.0, 0.02);

  auto les = maps.report.at("lesion").at("uv_centroid");
  EXPECT_NEAR(les[0].get<double>(), 0.25, 0.03);
  EXPECT_NEAR(les[1].get<double>(), v_at_fraction(tp.lesion_center_frac, p), 0.03);

  // The porphyrin patch stays on the dorsum: nothing on the underside (u near 0 or 1).
  for (int y = 0; y < tp.size; ++y)
    for (int x : {2, tp.size - 3}) EXPECT_LT(maps.porphyrin.at(x, y), 1e-3f);
  // Every map value is in [0, 1].
  for (float v : maps.porphyrin.value) ASSERT_TRUE(v >= 0 && v <= 1);
  for (float v : maps.lesion.value) ASSERT_TRUE(v >= 0 && v <= 1);
}

TEST(MeshTexture, Gray16PngRoundTrip) {
  UvMap m;
  m.size = 16;
  m.value.assign(256, 0.0f);
  m.covered.assign(256, 1);
  m.value[3 * 16 + 5] = 0.5f;
  m.value[15 * 16 + 15] = 1.0f;
  auto file = std::filesystem::temp_directory_path() / "ofl_gray16.png";
  write_gray16_png(file, m);
  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().nchannels, 1);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT16);
  std::vector<uint16_t> px(256);
  ASSERT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT16, px.data()));
  EXPECT_EQ(px[3 * 16 + 5], 32768);  // row 3 (v = 3.5/16) stays row 3: no flip
  EXPECT_EQ(px[255], 65535);
  EXPECT_EQ(px[0], 0);
}
