// Exposure control: auto exposure puts the chosen percentile pixel at the target
// share of full well, bracketing writes one raw per exposure named by it with the signal scaling
// as the exposure, and the DNG says the true f-number, focal length, exposure and capture time.
#include <gtest/gtest.h>

#include <utime.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>

#include <nlohmann/json.hpp>

#include "renderer/camera/camera_pipeline.h"
#include "renderer/image/spectral_exr.h"
#include "camera_test_util.h"

namespace ofl {
namespace {

using testing::box_camera;

// A ramp: radiance grows along x, so the percentile pixel is a definite one.
SpectralImage ramp_image(int w, int h) {
  SpectralImage img;
  img.resize(w, h, testing::bands(400, 700, 10));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int b = 0; b < img.bands(); ++b) img.pixel(x, y)[b] = static_cast<float>(1e-3 * (1 + x + 0.1 * y));
  return img;
}

double percentile_of(const CameraRun& run, double pct) {
  std::vector<double> v;
  for (float e : run.expected.mosaic_e) v.push_back(e + run.expected.dark_e);
  std::sort(v.begin(), v.end());
  size_t k = static_cast<size_t>(std::ceil(pct / 100.0 * v.size())) - 1;
  return v[k];
}

TEST(CameraExposure, AutoExposurePutsThePercentilePixelAtTheTarget) {
  CameraDescription cam = box_camera();
  cam.sensor.full_well_e = 10000;
  cam.sensor.dark_current_e_per_s = 200;  // dark electrons scale with the exposure too
  SpectralImage img = ramp_image(40, 30);
  for (auto [target, pct] : {std::pair{0.8, 99.5}, std::pair{0.5, 50.0}, std::pair{0.95, 100.0}}) {
    CameraRunOptions o;
    o.auto_exposure = true;
    o.auto_target = target;
    o.auto_percentile = pct;
    CameraRun run = simulate_camera(img, cam, o, "ramp");
    EXPECT_NEAR(percentile_of(run, pct) / (target * cam.sensor.full_well_e), 1.0, 1e-5) << target << " " << pct;
    EXPECT_EQ(run.exposure.how.at("mode"), "auto");
    EXPECT_DOUBLE_EQ(run.meta.exposure_s, run.exposure.exposure_s);
    // Whatever the starting exposure, the same answer.
    o.exposure_s = 1e-4;
    CameraRun again = simulate_camera(img, cam, o, "ramp");
    EXPECT_NEAR(again.exposure.exposure_s / run.exposure.exposure_s, 1.0, 1e-6);
  }
  // A black image keeps the starting exposure and says so.
  CameraRunOptions o;
  o.auto_exposure = true;
  CameraRun dark = simulate_camera(testing::uniform_image(8, 8, testing::bands(400, 700, 10), 0.0), box_camera(), o, "black");
  cam = box_camera();
  EXPECT_DOUBLE_EQ(dark.exposure.exposure_s, cam.sensor.exposure_s);
  bool said = false;
  for (auto& w : dark.warnings) said = said || w.find("no electrons") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(CameraExposure, BracketWritesOneRawPerExposureNamedByIt) {
  auto dir = testing::scratch("bracket");
  SpectralImage img = ramp_image(16, 12);
  img.attributes["oralfluor.vfov_deg"] = "20";
  write_spectral_exr(dir / "ramp.exr", img);
  std::string cam = std::string(OFL_SOURCE_DIR) + "/scenes/cameras/plain_rgb.json";
  auto r = testing::run_oralfluor("camera " + (dir / "ramp.exr").string() + " --camera " + cam + " -o " + (dir / "b").string() +
                                      " --exposure 0.01 --bracket 0.5,1,2 --noise off --json",
                                  dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["brackets"].size(), 3u);
  const double want[3] = {0.005, 0.01, 0.02};
  const char* names[3] = {"raw_5ms", "raw_10ms", "raw_20ms"};
  double g1 = j["brackets"][1]["channels"]["G"]["mean_expected_electrons"];
  for (int i = 0; i < 3; ++i) {
    const auto& b = j["brackets"][i];
    EXPECT_DOUBLE_EQ(b["exposure_s"].get<double>(), want[i]);
    for (const char* ext : {".tiff", ".json", ".dng"}) EXPECT_TRUE(std::filesystem::exists(dir / "b" / (std::string(names[i]) + ext))) << names[i] << ext;
    double g = b["channels"]["G"]["mean_expected_electrons"];
    EXPECT_NEAR(g / g1, want[i] / 0.01, 1e-6) << "expected electrons (photo + dark) scale with the exposure";
    auto side = nlohmann::json::parse(std::ifstream(dir / "b" / (std::string(names[i]) + ".json")));
    EXPECT_DOUBLE_EQ(side["exposure_s"].get<double>(), want[i]);
  }
  auto bad = testing::run_oralfluor("camera " + (dir / "ramp.exr").string() + " --camera " + cam + " -o " + (dir / "x").string() +
                                        " --exposure -1",
                                    dir);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--exposure"), std::string::npos) << bad.err;
}

TEST(CameraExposure, DngSaysTheFNumberFocalLengthExposureAndCaptureTime) {
  auto dir = testing::scratch("dng_meta");
  SpectralImage img = ramp_image(32, 24);  // dcraw reads no image narrower than 22 pixels
  write_spectral_exr(dir / "ramp.exr", img);
  nlohmann::json c = nlohmann::json::parse(std::ifstream(std::string(OFL_SOURCE_DIR) + "/scenes/cameras/oraleye.json"));
  c["lens"]["focal_length_mm"] = 4.5;
  c["lens"]["f_number"] = 2.8;
  c["sensor"]["qe"]["file"] = std::string(OFL_SOURCE_DIR) + "/assets/sensors/MT9V024_RGB.csv";
  std::ofstream(dir / "cam.json") << c.dump();
  setenv("SOURCE_DATE_EPOCH", "1700000000", 1);  // 2023-11-14 22:13:20 UTC
  auto r = testing::run_oralfluor("camera " + (dir / "ramp.exr").string() + " --camera " + (dir / "cam.json").string() + " -o " +
                                      (dir / "o").string() + " --exposure 0.025",
                                  dir);
  unsetenv("SOURCE_DATE_EPOCH");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string cmd = "TZ=UTC dcraw -i -v " + (dir / "o" / "raw.dng").string() + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string info;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) info += buf;
  ASSERT_EQ(pclose(p), 0) << "dcraw is installed by .ci/install-deps.sh: " << info;
  EXPECT_NE(info.find("Aperture: f/2.8"), std::string::npos) << info;
  EXPECT_NE(info.find("Focal length: 4.5 mm"), std::string::npos) << info;
  EXPECT_NE(info.find("Shutter: 1/40.0 sec"), std::string::npos) << info;
  EXPECT_NE(info.find("Timestamp: Tue Nov 14 22:13:20 2023"), std::string::npos) << info;

  // Without SOURCE_DATE_EPOCH the picture is dated when its radiance was made (the EXR's mtime).
  struct utimbuf when {1600000000, 1600000000};  // 2020-09-13 12:26:40 UTC
  ASSERT_EQ(utime((dir / "ramp.exr").c_str(), &when), 0);
  auto m = testing::run_oralfluor("camera " + (dir / "ramp.exr").string() + " --camera " + (dir / "cam.json").string() + " -o " +
                                      (dir / "m").string(),
                                  dir);
  ASSERT_EQ(m.exit_code, 0) << m.err;
  p = popen(("TZ=UTC dcraw -i -v " + (dir / "m" / "raw.dng").string() + " 2>&1").c_str(), "r");
  ASSERT_NE(p, nullptr);
  info.clear();
  while (fgets(buf, sizeof buf, p)) info += buf;
  pclose(p);
  EXPECT_NE(info.find("Timestamp: Sun Sep 13 12:26:40 2020"), std::string::npos) << info;
}

}  // namespace
}  // namespace ofl
