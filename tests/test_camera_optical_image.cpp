// The optical-image stage's geometry (renderer/camera/optics/optics.h): area-correct resampling of
// the render onto a sensor grid of its own conserves light, sensor pixels outside the render's
// field of view are zero and named in a warning, and blurring conserves light.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "camera_test_util.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/optics/optics.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"

using namespace ofl;
using namespace ofl::testing;

namespace {
constexpr double kPiT = 3.14159265358979323846;
constexpr double kVfov = 40, kFocal = 4.0;
constexpr int kW = 64, kH = 48;

// Side of a render pixel on the sensor plane (um), lens focused at infinity: f 2 tan(vfov/2) / H.
double render_pitch_um() { return kFocal * 1000.0 * 2.0 * std::tan(0.5 * kVfov * kPiT / 180.0) / kH; }

SpectralImage render(double L) {
  SpectralImage img = uniform_image(kW, kH, bands(405, 695, 10), L);
  img.attributes["oralfluor.vfov_deg"] = std::to_string(kVfov);
  return img;
}

CameraDescription camera_with_optics(int sw, int sh, double pitch_um, bool cos4) {
  CameraDescription c = box_camera();
  c.lens.focal_length_mm = kFocal;
  c.lens.cos4 = cos4;
  c.sensor.pixel_pitch_um = pitch_um;
  c.optics.enabled = true;
  c.optics.sensor_width_px = sw;
  c.optics.sensor_height_px = sh;
  return c;
}

double total_electrons(const CameraRun& r) {
  double s = 0;
  for (float e : r.expected.channel_e) s += e;
  return s;
}
}  // namespace

TEST(CameraOpticalImage, UniformSceneTotalElectronsDoNotDependOnTheSensorGrid) {
  // Reference: no optics stage, one sensor pixel per render pixel with the pitch that makes the
  // lens's field of view the render's (the camera module as it was). Then sensor grids of the
  // same physical size but other pixel counts (non-integer ratios to the render grid): the same
  // light falls on the same area, so the total electrons (all colours) must agree.
  SpectralImage img = render(0.02);
  for (bool cos4 : {false, true}) {
    CameraDescription ref = camera_with_optics(kW, kH, render_pitch_um(), cos4);
    ref.optics = OpticsDescription{};
    CameraRun base = simulate_camera(img, ref, {}, "uniform.exr");
    double want = total_electrons(base);
    ASSERT_GT(want, 0);
    for (auto [sw, sh] : {std::pair{100, 75}, std::pair{52, 39}, std::pair{64, 48}, std::pair{172, 129}}) {
      double pitch = render_pitch_um() * kW / sw;
      CameraRun r = simulate_camera(img, camera_with_optics(sw, sh, pitch, cos4), {}, "uniform.exr");
      ASSERT_EQ(r.expected.width, sw);
      EXPECT_NEAR(total_electrons(r) / want, 1.0, 1e-3) << sw << "x" << sh << (cos4 ? " cos4" : "");
      EXPECT_EQ(r.summary["optics"]["pixels_without_data"].get<int>(), 0);
    }
  }
}

TEST(CameraOpticalImage, ResamplingConservesLightOfAnyImage) {
  // Random radiance: sum of L x area on the sensor equals the render's, when the sensor holds the
  // whole field of view (here offset and larger than it).
  SpectralImage img = render(0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  for (auto& v : img.data) v = u(rng);
  OpticsDescription o;
  o.sensor_width_px = 131;
  o.sensor_height_px = 97;
  o.offset_x_um = 37.0;
  o.offset_y_um = -21.0;
  double pitch = 2.9;
  double pr = 1.7;  // render pixel side on the sensor
  RenderOnSensor m;
  m.scale = pr / pitch;
  m.render_pitch_um = pr;
  m.x0 = (-0.5 * kW * pr - o.offset_x_um) / pitch + 0.5 * o.sensor_width_px;
  m.y0 = (-0.5 * kH * pr - o.offset_y_um) / pitch + 0.5 * o.sensor_height_px;
  ASSERT_GT(m.x0, 0);
  ASSERT_LT(m.x0 + kW * m.scale, o.sensor_width_px);
  std::vector<float> cov;
  SpectralImage s = resample_to_sensor(img, o.sensor_width_px, o.sensor_height_px, m, &cov);
  for (int b = 0; b < img.bands(); ++b) {
    double in = 0, out = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) in += img.pixel(x, y)[b] * pr * pr;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) out += s.pixel(x, y)[b] * pitch * pitch;
    EXPECT_NEAR(out / in, 1.0, 1e-5) << "band " << b;
  }
  // The covered area is the render's field of view on the sensor.
  double covered = 0;
  for (float c : cov) covered += c;
  EXPECT_NEAR(covered, kW * kH * m.scale * m.scale, 1e-3);
}

TEST(CameraOpticalImage, SensorPixelsOutsideTheFieldOfViewAreZeroAndNamed) {
  // 100x75 sensor whose pitch puts the render's 64 columns on exactly 80 sensor columns (10..89)
  // and its 48 rows on 60 rows starting at 7.5: columns 0-9 and 90-99 and rows 0-6 and 68-74 get
  // no light (20 x 75 + 14 x 80 = 2620 pixels), rows 7 and 67 half (160 pixels partly covered).
  SpectralImage img = render(0.02);
  double pitch = render_pitch_um() * kW / 80.0;
  CameraRun r = simulate_camera(img, camera_with_optics(100, 75, pitch, false), {}, "uniform.exr");
  EXPECT_EQ(r.summary["optics"]["pixels_without_data"].get<int>(), 2620);
  EXPECT_EQ(r.summary["optics"]["pixels_partly_covered"].get<int>(), 160);
  std::string warning;
  for (auto& w : r.warnings)
    if (w.find("field of view does not cover") != std::string::npos) warning = w;
  ASSERT_FALSE(warning.empty());
  EXPECT_NE(warning.find("2620 pixels without data and 160 partly covered"), std::string::npos) << warning;
  EXPECT_NE(warning.find("columns 0-9 (left), columns 90-99 (right), rows 0-7 (top), rows 67-74 (bottom)"),
            std::string::npos) << warning;
  auto e = [&](int x, int y) { return r.expected.channel_e[(static_cast<size_t>(y) * 100 + x) * 3 + 1]; };
  EXPECT_EQ(e(5, 40), 0.0f);
  EXPECT_EQ(e(95, 40), 0.0f);
  EXPECT_EQ(e(50, 3), 0.0f);
  EXPECT_EQ(e(50, 72), 0.0f);
  EXPECT_GT(e(50, 40), 0.0f);
  EXPECT_NEAR(e(50, 7) / e(50, 40), 0.5, 1e-4);  // half covered
}

TEST(CameraOpticalImage, DepthLayeredBlurConservesLightAndKeepsUniformImagesUniform) {
  // Light inside the frame (a black border wider than any kernel): every band's total is kept
  // whatever each pixel's blur. A uniform image at one depth stays uniform (edges extended).
  SpectralImage img = render(0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<float> depth(kW * kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      depth[y * kW + x] = 40.0f + 30.0f * u(rng);  // mm: blur circles 0-43 um, up to 15 render pixels
      if (x >= 16 && x < kW - 16 && y >= 16 && y < kH - 16)
        for (int b = 0; b < img.bands(); ++b) img.pixel(x, y)[b] = u(rng);
    }
  LensDescription lens;
  lens.focal_length_mm = kFocal;
  lens.f_number = 2.0;
  OpticsDescription o;
  o.focus_distance_mm = 50;
  double pr = 3.0;
  nlohmann::json info;
  SpectralImage b = blur_optical_image(img, lens, o, pr, &depth, &info);
  ASSERT_GT(info["depth_layers"].size(), 3u);
  int biggest = 0;
  for (auto& l : info["depth_layers"]) biggest = std::max(biggest, l["kernel_size_px_first_band"].get<int>());
  ASSERT_LT(biggest, 32) << "kernels must fit in the black border";
  for (int k = 0; k < img.bands(); ++k) {
    double in = 0, out = 0;
    for (int i = 0; i < kW * kH; ++i) {
      in += img.data[i * img.bands() + k];
      out += b.data[i * img.bands() + k];
    }
    EXPECT_NEAR(out / in, 1.0, 1e-5) << "band " << k;
  }
  SpectralImage flat = render(1.0);
  std::vector<float> one_depth(kW * kH, 120.0f);
  SpectralImage fb = blur_optical_image(flat, lens, o, pr, &one_depth, nullptr);
  for (float v : fb.data) ASSERT_NEAR(v, 1.0f, 1e-5);
}

TEST(CameraOpticalImage, BlurCircleIsTheThinLensFormula) {
  LensDescription lens;
  lens.focal_length_mm = 4.0;
  lens.f_number = 2.0;
  OpticsDescription o;
  o.focus_distance_mm = 50;
  double A = 2.0, f = 4.0, df = 50;
  for (double d : {20.0, 40.0, 50.0, 80.0, 500.0}) {
    double c = A * f * std::fabs(d - df) / (d * (df - f)) * 1000.0;
    EXPECT_NEAR(blur_circle_um(lens, o, d), c, 1e-9 * (1 + c)) << d;
  }
  EXPECT_NEAR(blur_circle_um(lens, o, -1), A * f / (df - f) * 1000.0, 1e-9);  // at infinity
}

TEST(CameraOpticalImage, CliUsesTheStageWithAnOpticsSectionAndRejectsBadMtfFiles) {
  auto dir = scratch("optics_cli");
  SpectralImage img = render(0.02);
  write_spectral_exr(dir / "r.exr", img);
  const std::string sensor = R"("sensor": {"pixel_pitch_um": 3, "qe": {"R": 0.5, "G": 0.5, "B": 0.5},
      "exposure_s": 0.01, "system_gain_dn_per_e": 0.2, "full_well_e": 100000})";
  std::ofstream(dir / "cam.json") << R"({"lens": {"focal_length_mm": 4, "f_number": 2.8}, )" << sensor
                                  << R"(, "optics": {"sensor_pixels": [90, 60], "focus_distance_mm": 300}})";
  CommandResult r = run_oralfluor("camera " + (dir / "r.exr").string() + " --camera " + (dir / "cam.json").string() +
                                      " -o " + (dir / "out").string() + " --json --no-dng",
                                  dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["width"].get<int>(), 90);
  EXPECT_EQ(j["optics"]["sensor_pixels"][1].get<int>(), 60);
  // f = 4 mm focused at 300 mm: v = f d / (d - f) = 4.0540 mm, the render pixel 2 v tan(20 deg) / 48 on the sensor.
  double v = 4.0 * 300 / 296;
  EXPECT_NEAR(j["optics"]["image_distance_mm"].get<double>(), v, 1e-9);
  EXPECT_NEAR(j["optics"]["render_pixel_on_sensor_um"].get<double>(), v * 1000 * 2 * std::tan(20 * kPiT / 180) / 48, 1e-6);
  // Without the section the camera runs on the render grid as before.
  std::ofstream(dir / "plain.json") << R"({"lens": {"focal_length_mm": 4, "f_number": 2.8}, )" << sensor << "}";
  CommandResult p = run_oralfluor("camera " + (dir / "r.exr").string() + " --camera " + (dir / "plain.json").string() +
                                      " -o " + (dir / "out2").string() + " --json --no-dng",
                                  dir);
  ASSERT_EQ(p.exit_code, 0) << p.err;
  auto pj = nlohmann::json::parse(p.out);
  EXPECT_EQ(pj["width"].get<int>(), kW);
  EXPECT_FALSE(pj.contains("optics"));

  auto expect_error = [&](const std::string& cam, const std::string& what) {
    CommandResult e = run_oralfluor("camera " + (dir / "r.exr").string() + " --camera " + (dir / cam).string() +
                                        " -o " + (dir / "bad").string(),
                                    dir);
    EXPECT_EQ(e.exit_code, 2) << cam << ": " << e.err;
    EXPECT_NE(e.err.find(what), std::string::npos) << e.err;
  };
  std::ofstream(dir / "mtf.csv") << "wavelength_nm,frequency_cyc_per_mm,mtf\n550,0,1\n550,100,1.5\n";
  std::ofstream(dir / "badmtf.json") << R"({"lens": {"focal_length_mm": 4}, )" << sensor
                                     << R"(, "optics": {"sensor_pixels": [90, 60], "mtf_file": "mtf.csv"}})";
  expect_error("badmtf.json", "mtf.csv: line 3 column mtf: expected an MTF value in [-1, 1]");
  std::ofstream(dir / "mtf2.csv") << "wavelength_nm,freq,mtf\n550,0,1\n";
  std::ofstream(dir / "badmtf2.json") << R"({"lens": {"focal_length_mm": 4}, )" << sensor
                                      << R"(, "optics": {"sensor_pixels": [90, 60], "mtf_file": "mtf2.csv"}})";
  expect_error("badmtf2.json", "mtf2.csv");
  std::ofstream(dir / "nofocal.json") << "{" << sensor << R"(, "optics": {"sensor_pixels": [90, 60]}})";
  expect_error("nofocal.json", "nofocal.json: /optics: the optics stage needs lens.focal_length_mm");
  std::ofstream(dir / "both.json") << R"({"lens": {"focal_length_mm": 4, "magnification": -0.1}, )" << sensor
                                   << R"(, "optics": {"sensor_pixels": [90, 60], "focus_distance_mm": 300}})";
  expect_error("both.json", "both.json: /optics/focus_distance_mm: give either lens.magnification");
}

TEST(CameraOpticalImage, SensorOffsetMovesTheImageAndTheOpticalAxis) {
  // Sensor grid = render grid (same pitch), sensor centre 2 pixels right of the axis: render
  // column i lands on sensor column i - 2, and the cos^4 fall-off is centred 2 pixels left of the
  // sensor centre (between columns 29 and 30 of 64).
  SpectralImage img = render(0.0);
  for (int y = 0; y < kH; ++y)
    for (int b = 0; b < img.bands(); ++b) img.pixel(40, y)[b] = 1.0f;
  double pitch = render_pitch_um();
  CameraDescription cam = camera_with_optics(kW, kH, pitch, true);
  cam.optics.diffraction = false;
  cam.optics.offset_x_um = 2 * pitch;
  CameraRun r = simulate_camera(img, cam, {}, "column.exr");
  auto e = [&](const CameraRun& run, int x, int y) { return run.expected.channel_e[(static_cast<size_t>(y) * kW + x) * 3 + 1]; };
  EXPECT_GT(e(r, 38, 20), 0.0f);
  EXPECT_EQ(e(r, 37, 20), 0.0f);
  EXPECT_EQ(e(r, 39, 20), 0.0f);
  EXPECT_EQ(e(r, 40, 20), 0.0f);
  EXPECT_EQ(r.summary["field_geometry"]["axis_offset_px"][0].get<double>(), -2.0);
  // Uniform scene: the fall-off is symmetric about the shifted axis.
  CameraRun u = simulate_camera(render(0.02), cam, {}, "uniform.exr");
  EXPECT_NEAR(e(u, 29, 24) / e(u, 30, 24), 1.0, 1e-6);
  EXPECT_NEAR(e(u, 20, 24) / e(u, 39, 24), 1.0, 1e-6);
  EXPECT_GT(e(u, 30, 24), e(u, 32, 24));
}

TEST(CameraOpticalImage, MeasuredMtfFileOfADiffractionLimitedLensGivesTheAiryBlur) {
  // An MTF file holding the closed-form diffraction MTF at 450 and 650 nm (f/4) blurs a point like
  // the built-in Airy PSF; and the optics section survives the raw.json round trip.
  auto dir = scratch("optics_mtf");
  const double N = 4.0;
  {
    std::ofstream f(dir / "mtf.csv");
    f << "wavelength_nm,frequency_cyc_per_mm,mtf\n";
    for (double nm : {450.0, 650.0})
      for (int i = 0; i <= 200; ++i) {
        double x = i / 200.0, ln_mm = nm * 1e-6 * N;
        double m = x >= 1 ? 0 : 2.0 / kPiT * (std::acos(x) - x * std::sqrt(1 - x * x));
        f << nm << "," << x / ln_mm << "," << m << "\n";
      }
  }
  std::ofstream(dir / "cam.json") << R"({"lens": {"focal_length_mm": 4, "f_number": 4},
      "sensor": {"pixel_pitch_um": 3, "qe": {"R": 0.5, "G": 0.5, "B": 0.5}, "exposure_s": 0.01,
                 "system_gain_dn_per_e": 0.2, "full_well_e": 100000},
      "optics": {"sensor_pixels": [64, 48], "mtf_file": "mtf.csv", "focus_distance_mm": 500}})";
  CameraDescription measured = load_camera(dir / "cam.json");
  ASSERT_EQ(measured.optics.mtf.wavelength_nm.size(), 2u);
  CameraDescription airy = measured;
  airy.optics.mtf = MtfTable{};
  SpectralImage point;
  point.resize(81, 81, {450.0, 650.0});
  point.pixel(40, 40)[0] = point.pixel(40, 40)[1] = 1.0f;
  const double pr = 1.0;  // um per render pixel on the sensor
  SpectralImage a = blur_optical_image(point, airy.lens, airy.optics, pr, nullptr, nullptr);
  SpectralImage m = blur_optical_image(point, measured.lens, measured.optics, pr, nullptr, nullptr);
  for (int b = 0; b < 2; ++b) {
    double peak = a.pixel(40, 40)[b], worst = 0;
    ASSERT_GT(peak, 0.05);
    for (int y = 0; y < 81; ++y)
      for (int x = 0; x < 81; ++x) worst = std::max(worst, std::fabs(double(a.pixel(x, y)[b]) - m.pixel(x, y)[b]));
    EXPECT_LT(worst / peak, 0.01) << "band " << point.band_nm[b];
    EXPECT_GT(std::fabs(a.pixel(40, 40)[b] - a.pixel(40, 40)[1 - b]), 0.01) << "the two wavelengths must differ";
  }
  // raw.json round trip: the optics section (with the MTF file, absolute) and the focus come back.
  nlohmann::json j = camera_to_json(measured, 400, 700);
  auto back = parse_camera(JsonFile::from(j, "raw.json").root());
  EXPECT_TRUE(back.optics.enabled);
  EXPECT_EQ(back.optics.sensor_width_px, 64);
  EXPECT_EQ(back.optics.focus_distance_mm, 500);
  EXPECT_EQ(back.optics.mtf.wavelength_nm.size(), 2u);
  EXPECT_NEAR(back.lens.magnification, -4.0 / 496.0, 1e-12);
}

TEST(CameraOpticalImage, MeasuredPsfImagesThroughTheCliAndTheirErrors) {
  auto dir = scratch("optics_psf_images");
  SpectralImage img = render(0.02);
  write_spectral_exr(dir / "r.exr", img);
  const std::string head = R"({"lens": {"focal_length_mm": 4, "f_number": 2.8},
      "sensor": {"pixel_pitch_um": 3, "qe": {"R": 0.5, "G": 0.5, "B": 0.5}, "exposure_s": 0.01,
                 "system_gain_dn_per_e": 0.2, "full_well_e": 100000}, )";
  std::ofstream(dir / "psf.csv") << "a,b,c\n0,1,0\n1,4,1\n0,1,0\n";
  std::ofstream(dir / "ok.json") << head << R"("optics": {"sensor_pixels": [64, 48],
      "psf_images": [{"wavelength_nm": 550, "file": "psf.csv", "pitch_um": 20}]}})";
  CommandResult r = run_oralfluor("camera " + (dir / "r.exr").string() + " --camera " + (dir / "ok.json").string() +
                                      " -o " + (dir / "out").string() + " --json --no-dng",
                                  dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["optics"]["psf"].get<std::string>(), "measured PSF images");
  auto expect_error = [&](const std::string& name, const std::string& optics, const std::string& what) {
    std::ofstream(dir / name) << head << optics << "}";
    CommandResult e = run_oralfluor("camera " + (dir / "r.exr").string() + " --camera " + (dir / name).string() +
                                        " -o " + (dir / "bad").string(),
                                    dir);
    EXPECT_EQ(e.exit_code, 2) << name << ": " << e.err;
    EXPECT_NE(e.err.find(what), std::string::npos) << e.err;
  };
  std::ofstream(dir / "nan.csv") << "a,b\n0,1\n1,NaN\n";
  expect_error("nan.json", R"("optics": {"sensor_pixels": [64, 48], "psf_images": [{"wavelength_nm": 550, "file": "nan.csv", "pitch_um": 1}]})",
               "nan.csv: line 3 column 2: PSF value is NaN or infinite");
  std::ofstream(dir / "zero.csv") << "a,b\n0,0\n";
  expect_error("zero.json", R"("optics": {"sensor_pixels": [64, 48], "psf_images": [{"wavelength_nm": 550, "file": "zero.csv", "pitch_um": 1}]})",
               "zero.csv: the PSF image holds no positive value");
  // 3 samples of 10 mm: 30 mm on the sensor, 495 render pixels of 60.6 um.
  expect_error("wide.json", R"("optics": {"sensor_pixels": [64, 48], "psf_images": [{"wavelength_nm": 550, "file": "psf.csv", "pitch_um": 10000}]})",
               "psf.csv: pitch_um: the PSF image spans 494.");
  expect_error("nopitch.json", R"("optics": {"sensor_pixels": [64, 48], "psf_images": [{"wavelength_nm": 550, "file": "psf.csv"}]})",
               "nopitch.json: /optics/psf_images/0/pitch_um");
}

TEST(CameraOpticalImage, RenderPlaneSeenAtSensorPixelCentres) {
  // A 4x2 render plane whose pixels span 2 sensor pixels each, starting at sensor x 1, y 0.5, on a
  // 10x5 sensor: sensor column I sees render column floor((I + 0.5 - 1) / 2), row J render row
  // floor(J / 2); the rest is outside (-1). This is how `chroma --roi-material` finds the material
  // under each pixel of an optics-stage raw.
  std::vector<float> plane = {0, 1, 2, 3, 4, 5, 6, 7};
  auto s = render_plane_on_sensor(plane, 4, 2, 10, 5, {1, 0.5, 9, 4.5}, -1.0f);
  auto at = [&](int x, int y) { return s[static_cast<size_t>(y) * 10 + x]; };
  EXPECT_EQ(at(0, 0), -1.0f);
  EXPECT_EQ(at(1, 0), 0.0f);
  EXPECT_EQ(at(2, 1), 0.0f);
  EXPECT_EQ(at(3, 1), 1.0f);
  EXPECT_EQ(at(8, 0), 3.0f);
  EXPECT_EQ(at(9, 0), -1.0f);
  EXPECT_EQ(at(1, 2), 4.0f);
  EXPECT_EQ(at(8, 3), 7.0f);
  EXPECT_EQ(at(4, 4), -1.0f);
}

TEST(CameraOpticalImage, WarnsWhenAThinLensRenderWouldBeDefocusedTwice) {
  SpectralImage img = render(0.02);
  img.aovs["aov.depth"].assign(kW * kH, 0.2f);
  CameraDescription cam = camera_with_optics(kW, kH, render_pitch_um(), false);
  auto warned = [&](const SpectralImage& im) {
    for (auto& w : form_optical_image(im, cam, "r.exr").warnings)
      if (w.find("rendered with a thin lens") != std::string::npos) return true;
    return false;
  };
  img.attributes["oralfluor.camera_model"] = "pinhole";
  EXPECT_FALSE(warned(img));
  img.attributes["oralfluor.camera_model"] = "thin_lens";
  EXPECT_TRUE(warned(img));
  cam.optics.defocus = false;
  EXPECT_FALSE(warned(img));
}

TEST(CameraOpticalImage, HugeSensorsAndBlurCirclesAreRefusedOrCappedBeforeTheCost) {
  // A 100000x80000 sensor on 30 bands needs about 1 TB: an input error naming the field, before
  // any allocation.
  SpectralImage img = render(0.02);
  CameraDescription cam = camera_with_optics(100000, 80000, 0.01, false);
  cam.source = "huge.json";
  ::setenv("OFL_MEMORY_LIMIT_MIB", "4096", 1);
  try {
    form_optical_image(img, cam, "r.exr");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(e.describe().find("huge.json: /optics/sensor_pixels"), std::string::npos) << e.describe();
  }
  ::unsetenv("OFL_MEMORY_LIMIT_MIB");
  // Depths just beyond the focal length have enormous blur circles: capped at 64 render pixels,
  // with a warning that counts them (here the left half of the image).
  CameraDescription near = camera_with_optics(kW, kH, render_pitch_um(), false);
  near.lens.f_number = 0.5;  // an 8 mm aperture: blur circles of about 7 mm, over 100 render pixels of 61 um
  near.optics.focus_distance_mm = 500;
  SpectralImage one = uniform_image(kW, kH, {550.0}, 0.02);  // one band: the capped kernels are large
  one.attributes["oralfluor.vfov_deg"] = std::to_string(kVfov);
  one.aovs["aov.depth"].assign(kW * kH, 0.5f);  // m, in focus
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW / 2; ++x) one.aovs["aov.depth"][y * kW + x] = 0.0045f;
  std::string warning;
  for (auto& w : form_optical_image(one, near, "r.exr").warnings)
    if (w.find("blur circles above") != std::string::npos) warning = w;
  EXPECT_EQ(warning.rfind(std::to_string(kW / 2 * kH) + " render pixels have blur circles above 64", 0), 0u) << warning;
}
