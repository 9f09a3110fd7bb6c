// Light outside the image's bands is never lost quietly: the default bands are
// the whole grid, `render` and `camera` say how much LED light narrower bands drop (or `camera
// --strict` refuses), and the excitation leak the camera reports through a long-pass filter of
// optical density 6 .. 1 equals the closed-form integral of LED x reflectance x filter x QE.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include <nlohmann/json.hpp>

#include "renderer/validation/harness/bench_support.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/camera/optics/lens_optics.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/render/render_job.h"
#include "renderer/scene/scene.h"
#include "renderer/spectral/spectra/band_coverage.h"
#include "renderer/spectral/spectra/units.h"
#include "camera_test_util.h"
#include "cli_runner.h"

namespace ofl {
namespace {

using nlohmann::json;

constexpr double kPeak = 385, kFwhm = 12, kHeight = 0.1, kReflectance = 0.5;

double gaussian(double nm) {
  double s = kFwhm / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  return std::exp(-0.5 * (nm - kPeak) * (nm - kPeak) / (s * s)) / (s * std::sqrt(2.0 * kPi));
}

// A grey Lambertian patch under an isotropic 385 nm point LED 10 cm above its centre, seen from
// 30 cm with a 4 degree field: the centre pixels see L = R I(lambda) h / (pi r^3).
json violet_patch(const json& bands) {
  json j = {{"format", "oralfluor-scene"},
            {"version", 1},
            {"integrator", {{"spp", 64}, {"seed", 3}, {"max_depth", 1}, {"wavelengths", {{"min_nm", 350}, {"max_nm", 830}, {"step_nm", 5}}}}},
            {"camera", {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 4}, {"resolution", {16, 16}}}},
            {"materials", {{"patch", {{"type", "lambertian"}, {"reflectance", kReflectance}}}}},
            {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.2, 0, 0}}, {"v", {0, 0.2, 0}}, {"material", "patch"}}}},
            {"lights", {{{"type", "led"}, {"spd", {{"type", "gaussian"}, {"peak_nm", kPeak}, {"fwhm_nm", kFwhm}}},
                         {"radiant_intensity_W_sr", 1.0}, {"profile", {{"cos_power", 0}}}, {"position", {0, 0, kHeight}},
                         {"axis", {0, 0, -1}}}}}};
  if (!bands.is_null()) j["integrator"]["output_bands"] = bands;
  return j;
}

// The OralEye-like camera with its emission long-pass at optical density `od`, noise off.
CameraDescription oraleye_with_od(double od) {
  std::filesystem::path src = std::filesystem::path(OFL_SOURCE_DIR) / "scenes/cameras/oraleye.json";
  json j = json::parse(std::ifstream(src));
  j["filters"][0]["od"] = od;
  j["noise"] = false;
  j["sensor"]["qe"]["file"] = (std::filesystem::path(OFL_SOURCE_DIR) / "assets/sensors/MT9V024_RGB.csv").string();
  auto file = testing::scratch("camera_bands") / ("oraleye_od" + std::to_string(int(od)) + ".json");
  std::ofstream(file) << j.dump(2);
  return load_camera(file);
}

TEST(CameraBands, DefaultBandsAreTheWholeGrid) {
  Scene sc = load_scene(JsonFile::from(violet_patch(nullptr), "bands:default"));
  EXPECT_EQ(sc.integrator.bands.min_nm, 350);
  EXPECT_EQ(sc.integrator.bands.max_nm, 830);
  EXPECT_EQ(sc.integrator.bands.step_nm, 5);
  EXPECT_LT(led_light_outside_bands(sc).outside_share, 1e-12);
  EXPECT_EQ(led_band_warning(sc), "");
}

TEST(CameraBands, RenderAndCameraNameTheShareOfLedLightOutsideTheBands) {
  // Bands 400-700 nm: edges 397.5-702.5 nm. Closed form of the Gaussian's share below 397.5 nm.
  json narrow = {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", 5}};
  Scene sc = load_scene(JsonFile::from(violet_patch(narrow), "bands:narrow"));
  double s = kFwhm / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  double expected = 0.5 * std::erfc(-(397.5 - kPeak) / (s * std::sqrt(2.0)));
  BandCoverage c = led_light_outside_bands(sc);
  EXPECT_NEAR(c.outside_share, expected, 0.005) << "closed form " << expected;
  EXPECT_LE(c.outside_lo_nm, 365);
  EXPECT_EQ(c.outside_hi_nm, 397.5);
  std::string w = led_band_warning(sc);
  char share[32];
  std::snprintf(share, sizeof share, "%.1f %%", 100 * c.outside_share);
  EXPECT_NE(w.find(share), std::string::npos) << w;
  EXPECT_NE(w.find("397.5 nm"), std::string::npos) << w;

  // The camera finds the same share from the EXR's recorded LED spectrum, and --strict refuses.
  RenderOptions ro;
  ro.progress = false;
  RenderResult r = render(sc, ro);
  auto dir = testing::scratch("camera_bands_narrow");
  write_spectral_exr(dir / "radiance.exr", r.image);
  SpectralImage img = read_spectral_exr(dir / "radiance.exr");
  CameraDescription cam = oraleye_with_od(4);
  auto lost = lost_light_warnings(img, cam, nullptr);
  bool named = false;
  for (auto& l : lost) named = named || l.find(share) != std::string::npos;
  EXPECT_TRUE(named) << (lost.empty() ? "no warning" : lost.front());
  CameraRunOptions strict;
  strict.strict_bands = true;
  EXPECT_THROW(simulate_camera(img, cam, strict, (dir / "radiance.exr").string()), InputError);
  auto cli = test::run_cli("camera " + (dir / "radiance.exr").string() + " --camera " + OFL_SOURCE_DIR +
                           "/scenes/cameras/oraleye.json --strict -o " + (dir / "cam").string());
  EXPECT_EQ(cli.exit_code, 2) << cli.output;
  EXPECT_NE(cli.output.find("radiance.exr"), std::string::npos) << cli.output;
  auto warn = test::run_cli("camera " + (dir / "radiance.exr").string() + " --camera " + OFL_SOURCE_DIR +
                            "/scenes/cameras/oraleye.json -o " + (dir / "cam").string());
  EXPECT_EQ(warn.exit_code, 0) << warn.output;
  EXPECT_NE(warn.output.find(std::string("warning: ") + share), std::string::npos) << warn.output;
}

TEST(CameraBands, LeakThroughTheLongPassMatchesTheClosedFormFromOd6To1) {
  RenderOptions ro;
  ro.progress = false;
  // A 1 nm grid that ends at 500 nm (the light here is only 385 nm light; the camera's response
  // above is not exercised) and 2048 samples. 1 nm, because the camera takes each band's mean as
  // constant over the band: with 5 nm bands the QE table's start at 380 nm, on the LED's steep
  // flank, costs 1.6 % of the leak (measured), which is the bands' resolution, not a lost band.
  json j = violet_patch(nullptr);
  j["integrator"]["wavelengths"]["max_nm"] = 500;
  j["integrator"]["wavelengths"]["step_nm"] = 1;
  j["integrator"]["spp"] = 2048;
  Scene sc = load_scene(JsonFile::from(j, "bands:leak"));
  RenderResult r = render(sc, ro);
  const SpectralImage& img = r.image;
  // Centre 6 x 6 pixels: field angles below 0.8 degrees (the interference shift of the blocking
  // band is immaterial; cos^4 is in the closed form).
  const int x0 = 5, x1 = 11;
  // The render first: the band integral of the centre pixels' radiance against R I0 h / (pi r^3).
  {
    const auto& c = sc.camera;
    double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0), got = 0, want = 0;
    for (int y = x0; y < x1; ++y)
      for (int x = x0; x < x1; ++x) {
        for (int b = 0; b < img.bands(); ++b) got += img.pixel(x, y)[b] * (img.band_hi()[b] - img.band_lo()[b]);
        double px = (2.0 * (x + 0.5) / c.width - 1) * th * c.position.z, py = (1 - 2.0 * (y + 0.5) / c.height) * th * c.position.z;
        double rr = std::sqrt(px * px + py * py + kHeight * kHeight);
        want += kReflectance / kPi * kHeight / (rr * rr * rr);
      }
    std::printf("rendered radiance / closed form %.5f\n", got / want);
    EXPECT_NEAR(got / want, 1.0, 0.01) << "rendered " << got << " closed form " << want;
  }
  double prev = 0;
  for (double od : {6.0, 5.0, 4.0, 3.0, 2.0, 1.0}) {
    CameraDescription cam = oraleye_with_od(od);
    CameraRunOptions opt;
    opt.noise = false;
    CameraRun run = simulate_camera(img, cam, opt, "violet patch");
    for (auto& w : run.warnings) EXPECT_EQ(w.find("lies outside"), std::string::npos) << w;
    double reported = 0, closed = 0;
    const auto& c = sc.camera;
    double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0);
    double k = cam.sensor.exposure_s * cam.sensor.pixel_area_m2() * cam.sensor.fill_factor * kPi /
               (1.0 + 4.0 * cam.lens.f_number * cam.lens.f_number) * 1e-9 / (kPlanck * kSpeedOfLight);
    // Blue channel: the leak of 385 nm light through the long-pass (the patch does not fluoresce).
    double integral = 0;
    for (double nm = 340; nm <= 840; nm += 0.02) integral += gaussian(nm) * system_qe(cam, 2, nm, 0, 0) * nm * 0.02;
    for (int y = x0; y < x1; ++y)
      for (int x = x0; x < x1; ++x) {
        reported += run.expected.channel_e[(size_t(y) * img.width + x) * 3 + 2];
        double px = (2.0 * (x + 0.5) / c.width - 1) * th * c.position.z, py = (1 - 2.0 * (y + 0.5) / c.height) * th * c.position.z;
        double rr = std::sqrt(px * px + py * py + kHeight * kHeight);
        double cos_field = c.position.z / std::sqrt(px * px + py * py + c.position.z * c.position.z);
        closed += k * kReflectance / kPi * kHeight / (rr * rr * rr) * std::pow(cos_field, 4) * integral;
      }
    std::printf("OD %.0f: leak %.6g e per pixel, closed form %.6g e, ratio %.5f\n", od, reported / 36, closed / 36,
                reported / closed);
    EXPECT_NEAR(reported / closed, 1.0, 0.01) << "OD " << od << ": camera " << reported / 36 << " e, closed form "
                                              << closed / 36 << " e";
    if (prev > 0) EXPECT_GT(reported, 5 * prev) << "one OD less must pass about 10x more";
    prev = reported;
  }
}

}  // namespace
}  // namespace ofl
