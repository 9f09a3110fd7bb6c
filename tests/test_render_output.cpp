// Render determinism across thread counts, and the spectral EXR layout read back with OpenEXR's
// own API (channel names and header attributes exactly as docs/architecture.md, "Conventions", and renderer/image/spectral_exr.h give them).
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStringAttribute.h>
#include <tbb/global_control.h>

#include <cstring>
#include <sstream>
#include "cli_runner.h"
#include <filesystem>
#include <fstream>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/render/render_job.h"

using namespace ofl;

namespace {
Scene small_scene(int spp) {
  auto file = std::filesystem::path(OFL_SOURCE_DIR) / "benchmarks/scenes/tongue_mouth.json";
  SceneOverrides ov;
  ov.spp = spp;
  ov.width = 48;
  ov.height = 40;
  return load_scene(file, ov);
}
}  // namespace

TEST(Render, BitIdenticalWithOneAndTwoThreads) {
  Scene sc = small_scene(4);
  RenderResult a, b;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    a = render(sc);
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    b = render(sc);
  }
  ASSERT_EQ(a.image.data.size(), b.image.data.size());
  EXPECT_EQ(0, std::memcmp(a.image.data.data(), b.image.data.data(), a.image.data.size() * sizeof(float)));
  // And the image is not trivially empty.
  double s = 0;
  for (float v : a.image.data) s += v;
  EXPECT_GT(s, 0);
}

TEST(Render, DifferentSeedsGiveDifferentNoise) {
  Scene sc = small_scene(2);
  RenderResult a = render(sc);
  sc.integrator.seed = 99;
  RenderResult b = render(sc);
  EXPECT_NE(0, std::memcmp(a.image.data.data(), b.image.data.data(), a.image.data.size() * sizeof(float)));
}

// A chunk whose size field claims more than the file holds is refused before OpenEXR allocates it
// (fuzz_spectral_exr: 8 kB files with chunks of 1.6-1.8 GB; tests/fuzz/regressions/spectral_exr),
// and the unmodified file (ZIP chunks of 16 lines, with the table intact) still reads.
TEST(SpectralExr, ChunkSizesAreCheckedAgainstTheFile) {
  Scene sc = small_scene(1);
  RenderResult r = render(sc);
  const std::string bytes = spectral_exr_bytes(r.image);
  auto dir = std::filesystem::temp_directory_path();
  auto good = dir / "ofl_chunks_good.exr", bad = dir / "ofl_chunks_bad.exr";
  { std::ofstream(good, std::ios::binary) << bytes; }
  SpectralImage back = read_spectral_exr(good);
  EXPECT_EQ(back.width, r.image.width);
  // The first chunk's offset is the first entry of the line offset table, right after the header:
  // find it as the smallest offset that points inside the file past a run of 8-byte entries.
  Imf::InputFile in(good.c_str());
  const int chunks = (r.image.height + 15) / 16;
  size_t table = 0;
  for (size_t p = 8; p + 8 * size_t(chunks) <= bytes.size(); ++p) {
    uint64_t first = 0;
    std::memcpy(&first, bytes.data() + p, 8);
    if (first == p + 8 * size_t(chunks)) { table = p; break; }
  }
  ASSERT_GT(table, 0u) << "no line offset table found";
  std::string b = bytes;
  const uint32_t huge = 1768776960u;  // the fuzzer's size
  std::memcpy(&b[table + 8 * size_t(chunks) + 4], &huge, 4);
  { std::ofstream(bad, std::ios::binary) << b; }
  try {
    read_spectral_exr(bad);
    ADD_FAILURE() << "a chunk of 1.7 GB in a small file was read";
  } catch (const InputError& e) {
    EXPECT_NE(e.describe().find(bad.string() + ": chunk 0: claims 1768776960 bytes of pixel data"), std::string::npos) << e.describe();
  }
  std::filesystem::remove(good);
  std::filesystem::remove(bad);
}

TEST(SpectralExr, ChannelNamesAndAttributesExactly) {
  Scene sc = small_scene(1);
  RenderResult r = render(sc);
  auto file = std::filesystem::temp_directory_path() / "ofl_layout_test.exr";
  write_spectral_exr(file, r.image);

  Imf::InputFile in(file.c_str());
  const Imf::Header& h = in.header();
  auto* ver = h.findTypedAttribute<Imf::StringAttribute>("spectralLayoutVersion");
  ASSERT_NE(ver, nullptr);
  EXPECT_EQ(ver->value(), "1.0");
  auto* units = h.findTypedAttribute<Imf::StringAttribute>("emissiveUnits");
  ASSERT_NE(units, nullptr);
  EXPECT_EQ(units->value(), "W.m^-2.sr^-1");
  std::set<std::string> names;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) names.insert(it.name());
  // Default output bands: 400-700 nm every 10 nm -> 31 spectral channels plus R, G, B, plus the
  // six aov.* planes (this scene has no fluorescence, so no fluorescence layer).
  EXPECT_EQ(names.size(), 31u + 3u + 6u);
  for (const char* a : {"aov.material", "aov.u", "aov.v", "aov.depth", "aov.cos_view", "aov.irradiance"}) EXPECT_TRUE(names.count(a)) << a;
  for (int nm = 400; nm <= 700; nm += 10) EXPECT_TRUE(names.count("S0." + std::to_string(nm) + ",000000nm")) << nm;
  for (const char* c : {"R", "G", "B"}) EXPECT_TRUE(names.count(c));
  EXPECT_EQ(spectral_channel_name(550.0), "S0.550,000000nm");
  EXPECT_EQ(spectral_channel_name(412.5), "S0.412,500000nm");

  // Our reader returns what was written.
  SpectralImage back = read_spectral_exr(file);
  ASSERT_EQ(back.bands(), 31);
  EXPECT_EQ(back.band_nm.front(), 400);
  EXPECT_EQ(back.band_nm.back(), 700);
  EXPECT_EQ(0, std::memcmp(back.data.data(), r.image.data.data(), r.image.data.size() * sizeof(float)));
  EXPECT_EQ(back.attributes.at("oralfluor.spp"), "1");
}

TEST(SceneOverrides, OneSideAloneKeepsTheAspectRatioBothSetTheSize) {
  auto file = std::filesystem::path(OFL_SOURCE_DIR) / "benchmarks/scenes/tongue_mouth.json";
  Scene full = load_scene(file);
  double aspect = double(full.camera.height) / full.camera.width;
  SceneOverrides w;
  w.width = 160;
  Scene a = load_scene(file, w);
  EXPECT_EQ(a.camera.width, 160);
  EXPECT_EQ(a.camera.height, std::lround(160 * aspect));
  SceneOverrides h;
  h.height = 90;
  Scene b = load_scene(file, h);
  EXPECT_EQ(b.camera.height, 90);
  EXPECT_EQ(b.camera.width, std::lround(90 / aspect));
  SceneOverrides both;
  both.width = 33;
  both.height = 7;
  Scene c = load_scene(file, both);
  EXPECT_EQ(c.camera.width, 33);
  EXPECT_EQ(c.camera.height, 7);
}

TEST(Progress, LogsGetPlainLinesWhenStderrIsNotATerminal) {
  // popen gives the command a pipe, as a batch system's log would.
  auto out = std::filesystem::temp_directory_path() / "ofl_progress_log";
  std::filesystem::remove_all(out);
  setenv("OFL_PROGRESS_SECONDS", "0.05", 1);
  auto r = test::run_cli("render " + std::string(OFL_SOURCE_DIR) + "/benchmarks/scenes/tongue_mouth.json --width 96 --spp 256 -o " +
                         out.string());
  unsetenv("OFL_PROGRESS_SECONDS");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::istringstream in(r.output);
  std::string line, last;
  int lines = 0;
  while (std::getline(in, line))
    if (line.rfind("render: ", 0) == 0 && line.find(" %") != std::string::npos) {
      EXPECT_EQ(line.find('\r'), std::string::npos) << "no carriage returns in a log";
      ++lines;
      last = line;
    }
  EXPECT_GE(lines, 1) << r.output;  // the final line always; more only if the render outlasts 0.05 s (not asserted: no wall clock)
  EXPECT_NE(last.find("100.0 %"), std::string::npos) << last;
  std::filesystem::remove_all(out);
}
