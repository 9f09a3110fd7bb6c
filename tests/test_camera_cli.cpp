// `oralfluor camera` end to end: the files it writes and what is in them, the DNG as a standard raw
// tool decodes it, determinism across --threads, and one-line errors with exit code 2.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <fstream>

#include "camera_test_util.h"
#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/camera/raw/raw_writer.h"
#include "renderer/image/spectral_exr.h"

using namespace ofl;
using namespace ofl::testing;

namespace {
const std::string kOralEye = std::string(OFL_SOURCE_DIR) + "/scenes/cameras/oraleye.json";

std::filesystem::path small_chart(const std::filesystem::path& dir) {
  auto p = dir / "chart.exr";
  write_spectral_exr(p, make_fluorescence_chart(small_chart_options()));
  return p;
}

std::vector<uint16_t> read_u16(const std::filesystem::path& p, int* channels = nullptr) {
  auto in = OIIO::ImageInput::open(p.string());
  if (!in) return {};
  std::vector<uint16_t> px(in->spec().image_pixels() * in->spec().nchannels);
  in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::UINT16, px.data());
  if (channels) *channels = in->spec().nchannels;
  return px;
}

bool have(const char* tool) { return std::system((std::string("command -v ") + tool + " > /dev/null 2>&1").c_str()) == 0; }
}  // namespace

TEST(CameraCli, WritesRawSidecarDngElectronsAndPreview) {
  auto dir = scratch("cli_outputs");
  auto exr = small_chart(dir);
  auto out = dir / "out";
  CommandResult r = run_oralfluor("camera " + exr.string() + " --camera " + kOralEye + " -o " + out.string() + " --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json s = nlohmann::json::parse(r.out);
  for (const char* f : {"raw.tiff", "raw.json", "raw.dng", "electrons.exr", "camera_preview.png"})
    EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;

  // The TIFF and its sidecar carry the raw numbers.
  RawImage raw = read_raw(out / "raw.tiff");
  EXPECT_EQ(raw.width, 48);
  EXPECT_EQ(raw.height, 32);
  EXPECT_EQ(raw.meta.cfa, CfaPattern::kRGGB);
  EXPECT_EQ(raw.meta.black_level_dn, 32);
  EXPECT_EQ(raw.meta.white_level_dn, 992);  // round(20000 e- * 0.048 DN/e-) + 32, below the 10-bit 1023
  EXPECT_EQ(raw.meta.bit_depth, 10);
  EXPECT_DOUBLE_EQ(raw.meta.exposure_s, 0.033);
  EXPECT_TRUE(raw.sidecar.contains("camera"));
  EXPECT_TRUE(raw.sidecar["exr_attributes"].contains("oralfluor.excitation_spd"));
  EXPECT_EQ(raw.sidecar["field_geometry"]["source"], "render_vfov");
  auto in = OIIO::ImageInput::open((out / "raw.tiff").string());
  ASSERT_TRUE(in);
  auto desc = nlohmann::json::parse(in->spec().get_string_attribute("ImageDescription"));
  EXPECT_EQ(desc["cfa_pattern"], "RGGB");
  EXPECT_EQ(desc["white_level_dn"], 992);
  EXPECT_EQ(desc["total_gain_dn_per_e"], 0.048);

  // The summary's channel means are the raw means.
  double sum[3] = {0, 0, 0}, n[3] = {0, 0, 0};
  for (int y = 0; y < raw.height; ++y)
    for (int x = 0; x < raw.width; ++x) {
      int c = cfa_channel(raw.meta.cfa, x, y);
      sum[c] += raw.dn[static_cast<size_t>(y) * raw.width + x];
      n[c] += 1;
    }
  EXPECT_NEAR(s["channels"]["R"]["mean_dn"].get<double>(), sum[0] / n[0], 1e-9);
  EXPECT_NEAR(s["channels"]["B"]["mean_dn"].get<double>(), sum[2] / n[2], 1e-9);

  // electrons.exr: R, G, B and the mosaic (own colour + dark electrons).
  auto ein = OIIO::ImageInput::open((out / "electrons.exr").string());
  ASSERT_TRUE(ein);
  ASSERT_EQ(ein->spec().nchannels, 4);
  EXPECT_EQ(ein->spec().channelnames[3], "mosaic");
  std::vector<float> e(ein->spec().image_pixels() * 4);
  ein->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, e.data());
  double dark = s["dark_electrons"].get<double>();
  EXPECT_NEAR(e[3], e[0] + dark, 1e-3 * e[3]);          // (0, 0) is red
  EXPECT_NEAR(e[4 * 1 + 3], e[4 * 1 + 1] + dark, 1e-3 * e[7]);  // (1, 0) is green

  // A standard raw decoder reads the DNG as the same mosaic (dcraw -D: no scaling).
  // .ci/install-deps.sh installs dcraw, so a missing decoder is a set-up failure, not a skip.
  ASSERT_TRUE(have("dcraw")) << "dcraw not installed (run .ci/install-deps.sh)";
  auto dec = dir / "dcraw.tiff";
  ASSERT_EQ(std::system(("dcraw -D -4 -T -c " + (out / "raw.dng").string() + " > " + dec.string()).c_str()), 0);
  int ch = 0;
  EXPECT_EQ(read_u16(dec, &ch), raw.dn);
  EXPECT_EQ(ch, 1);
  std::system(("dcraw -i -v " + (out / "raw.dng").string() + " > " + (dir / "info.txt").string()).c_str());
  std::ifstream f(dir / "info.txt");
  std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("Filter pattern: RG/GB"), std::string::npos) << text;
  EXPECT_NE(text.find("Camera: oralfluor oraleye-like"), std::string::npos) << text;
}

TEST(CameraCli, SameSeedSameRawWithOneOrTwoThreads) {
  auto dir = scratch("cli_threads");
  auto exr = small_chart(dir);
  auto run = [&](const std::string& extra, const std::string& name) {
    auto out = dir / name;
    CommandResult r = run_oralfluor(extra + " camera " + exr.string() + " --camera " + kOralEye + " -o " + out.string() +
                                        " --no-dng",
                                    dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return read_u16(out / "raw.tiff");
  };
  auto a = run("--threads 1", "t1"), b = run("--threads 2", "t2");
  auto d = run("", "all_threads");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, d);
  auto dir2 = dir / "seed9";
  CommandResult r = run_oralfluor("camera " + exr.string() + " --camera " + kOralEye + " -o " + dir2.string() + " --seed 9", dir);
  ASSERT_EQ(r.exit_code, 0);
  EXPECT_NE(read_u16(dir2 / "raw.tiff"), a);
}

TEST(CameraCli, BadInputsGiveOneLineErrorAndExitCode2) {
  auto dir = scratch("cli_errors");
  auto exr = small_chart(dir);
  auto expect_error = [&](const std::string& args, const std::string& must_contain) {
    CommandResult r = run_oralfluor(args, dir);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(must_contain), std::string::npos) << "expected \"" << must_contain << "\" in: " << r.err;
  };
  // Missing and non-spectral EXR.
  expect_error("camera " + (dir / "missing.exr").string() + " --camera " + kOralEye, "missing.exr: file not found");
  {
    auto rgb = dir / "rgb.exr";
    auto out = OIIO::ImageOutput::create(rgb.string());
    OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::FLOAT);
    std::vector<float> px(48, 0.5f);
    out->open(rgb.string(), spec);
    out->write_image(OIIO::TypeDesc::FLOAT, px.data());
    out->close();
    expect_error("camera " + rgb.string() + " --camera " + kOralEye, "rgb.exr: channels: no spectral channels");
  }
  // Bad camera JSON: unknown field, wrong type, QE with NaN.
  std::ofstream(dir / "typo.json") << R"({"sensor": {"pixel_pitch_um": 3, "qe": {"R": 0.5, "G": 0.5, "B": 0.5},
      "exposure_s": 0.01, "system_gain_dn_per_e": 0.2, "full_well_e": 10000, "read_nosie_e": 2}})";
  expect_error("camera " + exr.string() + " --camera " + (dir / "typo.json").string(), "typo.json: /sensor/read_nosie_e: unknown field");
  std::ofstream(dir / "type.json") << R"({"sensor": {"pixel_pitch_um": "3", "qe": {"R": 0.5, "G": 0.5, "B": 0.5},
      "exposure_s": 0.01, "system_gain_dn_per_e": 0.2, "full_well_e": 10000}})";
  expect_error("camera " + exr.string() + " --camera " + (dir / "type.json").string(), "type.json: /sensor/pixel_pitch_um: expected a number");
  std::ofstream(dir / "qe.csv") << "wavelength_nm,r,g,b\n400,0.1,0.2,0.3\n500,0.1,0.2,NaN\n";
  std::ofstream(dir / "nan.json") << R"({"sensor": {"pixel_pitch_um": 3, "qe": {"file": "qe.csv"}, "exposure_s": 0.01,
      "system_gain_dn_per_e": 0.2, "full_well_e": 10000}})";
  expect_error("camera " + exr.string() + " --camera " + (dir / "nan.json").string(), "qe.csv: line 3 column \"b\": value is NaN");
  expect_error("camera " + exr.string() + " --camera " + (dir / "absent.json").string(), "absent.json: cannot open file");

  // chroma: bad ROI, ROI outside the image, a file that is not a raw mosaic.
  auto out = dir / "out";
  ASSERT_EQ(run_oralfluor("camera " + exr.string() + " --camera " + kOralEye + " -o " + out.string(), dir).exit_code, 0);
  expect_error("chroma " + (out / "raw.tiff").string() + " --roi 1,2,3", "--roi: expected x,y,w,h");
  expect_error("chroma " + (out / "raw.tiff").string() + " --roi 40,0,16,16", "--roi: region 40,0,16,16 leaves the 48x32 image");
  expect_error("chroma " + (out / "camera_preview.png").string() + " --roi 0,0,8,8", "not a raw mosaic: 3 channels");
  expect_error("chroma " + (dir / "nothing.tiff").string() + " --roi 0,0,8,8", "nothing.tiff: file not found");
  expect_error("chroma " + (out / "raw.tiff").string() + " --roi 0,0,8,8 --led " + (dir / "noled.csv").string(),
               "noled.csv: --led: file not found");
}

TEST(CameraCli, ForeignSpectralExrWithoutOralfluorAttributes) {
  // An EXR as another renderer might write it: point as decimal separator, channels out of order,
  // an extra Y channel, none of the oralfluor.* attributes. The camera runs on axis with a warning,
  // and chroma still gives statistics without reference lines.
  auto dir = scratch("cli_foreign");
  auto exr = dir / "foreign.exr";
  std::vector<std::string> names = {"Y"};
  for (int nm = 700; nm >= 400; nm -= 20) names.push_back("S0." + std::to_string(nm) + ".000000nm");
  const int w = 16, h = 12, nc = static_cast<int>(names.size());
  OIIO::ImageSpec spec(w, h, nc, OIIO::TypeDesc::FLOAT);
  spec.channelnames = names;
  std::vector<float> px(static_cast<size_t>(w) * h * nc, 0.02f);
  auto out = OIIO::ImageOutput::create(exr.string());
  ASSERT_TRUE(out && out->open(exr.string(), spec));
  out->write_image(OIIO::TypeDesc::FLOAT, px.data());
  out->close();
  auto o = dir / "out";
  CommandResult r = run_oralfluor("camera " + exr.string() + " --camera " + kOralEye + " -o " + o.string() + " --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json s = nlohmann::json::parse(r.out);
  EXPECT_EQ(s["field_geometry"]["source"], "none");
  EXPECT_NE(r.err.find("field angles are taken as zero"), std::string::npos) << r.err;
  EXPECT_GT(s["channels"]["G"]["mean_expected_electrons"].get<double>(), 0.0);
  CommandResult c = run_oralfluor("chroma " + (o / "raw.tiff").string() + " --roi 0,0,16,12 --json", dir);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_NE(c.err.find("no LED spectrum"), std::string::npos) << c.err;
  EXPECT_EQ(nlohmann::json::parse(c.out)["lines"].size(), 0u);
}
