// The README's walk through scenes/minimal.json states the defaults a scene leaves out; the output
// bands it names must be the ones the binary writes (it once said 400-700 nm while the binary wrote
// the whole transport grid). Renders the minimal scene tiny and compares the EXR's band centres with
// the numbers in the README's sentence.
#include <gtest/gtest.h>

#include <regex>

#include "renderer/image/spectral_exr.h"
#include "tests/cli_runner.h"

TEST(ReadmeDefaults, OutputBandsAreTheOnesTheBinaryWrites) {
  const std::filesystem::path src = OFL_SOURCE_DIR;
  const std::string readme = ofl::test::slurp(src / "README.md");
  std::smatch m;
  const std::regex sentence(R"(output bands the whole grid \((\d+) bands of (\d+) nm, (\d+)-(\d+) nm)");
  ASSERT_TRUE(std::regex_search(readme, m, sentence)) << "README.md no longer states the default output bands";
  const int count = std::stoi(m[1]), step = std::stoi(m[2]), lo = std::stoi(m[3]), hi = std::stoi(m[4]);

  const auto dir = ofl::test::fresh_dir("readme_defaults");
  auto r = ofl::test::run_cli("render " + (src / "scenes" / "minimal.json").string() + " --width 4 --height 4 --spp 1 -o " +
                              dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ofl::SpectralImage img = ofl::read_spectral_exr(dir / "radiance.exr");
  ASSERT_EQ(int(img.band_nm.size()), count);
  EXPECT_DOUBLE_EQ(img.band_nm.front(), lo);
  EXPECT_DOUBLE_EQ(img.band_nm.back(), hi);
  EXPECT_DOUBLE_EQ(img.band_nm[1] - img.band_nm[0], step);
  std::filesystem::remove_all(dir);
}
