// Previews that show what matters under violet light: next to the radiance
// preview, `render` writes the fluorescence alone and, with --camera, the image through the camera.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "camera_test_util.h"

namespace ofl {
namespace {

std::array<double, 3> channel_means(const std::filesystem::path& png) {
  auto in = OIIO::ImageInput::open(png.string());
  EXPECT_TRUE(in) << png;
  if (!in) return {0, 0, 0};
  const auto& spec = in->spec();
  std::vector<float> px(size_t(spec.width) * spec.height * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data());
  std::array<double, 3> m{0, 0, 0};
  for (size_t i = 0; i < px.size(); i += spec.nchannels)
    for (int c = 0; c < 3; ++c) m[c] += px[i + c];
  for (double& v : m) v /= double(spec.width) * spec.height;
  return m;
}

std::string bytes(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

TEST(Previews, FluorescenceAloneAndThroughTheCameraBesideTheRadiance) {
  auto dir = testing::scratch("previews");
  std::string src = OFL_SOURCE_DIR, cam = src + "/scenes/cameras/oraleye.json";
  // A grey patch with FAD (emission near 530 nm) under a 405 nm LED.
  auto r = testing::run_oralfluor("render " + src + "/scenes/minimal.json --width 48 --spp 8 --camera " + cam + " -o " +
                                      (dir / "r").string(),
                                  dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto radiance = channel_means(dir / "r" / "preview.png");
  auto fl = channel_means(dir / "r" / "preview_fluorescence.png");
  // The radiance is dominated by reflected violet light; the fluorescence alone is FAD's green.
  EXPECT_GT(radiance[2], radiance[1]) << "violet LED light: blue above green";
  EXPECT_GT(fl[1], 1.5 * fl[0]) << "FAD: green above red";
  EXPECT_GT(fl[1], 1.5 * fl[2]) << "FAD: green above blue";
  // The camera preview is what `oralfluor camera --noise off` previews, byte for byte.
  auto c = testing::run_oralfluor("camera " + (dir / "r" / "radiance.exr").string() + " --camera " + cam + " --noise off -o " +
                                      (dir / "c").string(),
                                  dir);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  std::string a = bytes(dir / "r" / "preview_camera.png"), b = bytes(dir / "c" / "camera_preview.png");
  EXPECT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "render --camera preview differs from oralfluor camera's";
  // Without fluorescence in the scene there is no fluorescence layer and no such preview.
  auto n = testing::run_oralfluor("render " + src + "/benchmarks/scenes/tongue_mouth.json --width 32 --spp 1 -o " +
                                      (dir / "n").string(),
                                  dir);
  ASSERT_EQ(n.exit_code, 0) << n.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "n" / "preview_fluorescence.png"));
}

}  // namespace
}  // namespace ofl
