// Chromaticity analysis: per-cell r, g from a mosaic, ROI statistics and ellipse, invariance to the
// light level, and the fluorophore reference lines (figure 5 construction of the reference paper).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <fstream>

#include "camera_test_util.h"
#include "renderer/analysis/chroma_reference.h"
#include "renderer/analysis/chromaticity.h"
#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"

using namespace ofl;
using namespace ofl::testing;

namespace {
constexpr double kPiT = 3.14159265358979323846;
const std::string kOralEye = std::string(OFL_SOURCE_DIR) + "/scenes/cameras/oraleye.json";

}  // namespace

TEST(Chroma, CellChromaticityFromAHandMadeMosaic) {
  // GRBG, black 10, white 1000; two 2x2 cells side by side and a saturated third.
  //   cell 0: G1 = 210, R = 110, B = 60, G2 = 230  -> R 100, G (200 + 220) / 2 = 210, B 50
  //   cell 1: G1 = 110, R = 310, B = 110, G2 = 110 -> R 300, G 100, B 100
  //   cell 2: R at the white level                  -> left out
  std::vector<uint16_t> dn = {210, 110, 110, 310, 500, 1000,  //
                              60,  230, 110, 110, 500, 500};
  ChromaStats s = roi_chromaticity(dn, 6, 2, CfaPattern::kGRBG, 10, 1000, {0, 0, 6, 2});
  EXPECT_EQ(s.cells, 3u);
  EXPECT_EQ(s.saturated, 1u);
  ASSERT_EQ(s.used, 2u);
  double r0 = 100.0 / 360, g0 = 210.0 / 360, r1 = 300.0 / 500, g1 = 100.0 / 500;
  EXPECT_NEAR(s.rg[0][0], r0, 1e-15);
  EXPECT_NEAR(s.rg[0][1], g0, 1e-15);
  EXPECT_NEAR(s.rg[1][0], r1, 1e-15);
  EXPECT_NEAR(s.mean_r, 0.5 * (r0 + r1), 1e-15);
  EXPECT_NEAR(s.mean_g, 0.5 * (g0 + g1), 1e-15);
  // Sample covariance of two points: (d d^T) / 2 with d = p1 - p0... times 2 / (n - 1) = 1/2.
  EXPECT_NEAR(s.cov_rr, 0.5 * (r1 - r0) * (r1 - r0), 1e-15);
  EXPECT_NEAR(s.cov_rg, 0.5 * (r1 - r0) * (g1 - g0), 1e-15);
  EXPECT_NEAR(s.mean_rgb[0], 200.0, 1e-12);
  ChromaStats with_sat = roi_chromaticity(dn, 6, 2, CfaPattern::kGRBG, 10, 1000, {0, 0, 6, 2}, true);
  EXPECT_EQ(with_sat.used, 3u);
  // An ROI starting at an odd pixel uses only the cells completely inside it.
  ChromaStats odd = roi_chromaticity(dn, 6, 2, CfaPattern::kGRBG, 10, 1000, {1, 0, 4, 2});
  EXPECT_EQ(odd.cells, 1u);
  EXPECT_NEAR(odd.rg[0][0], r1, 1e-15);
}

TEST(Chroma, EllipseHoldsNinetyFivePercent) {
  Ellipse e = covariance_ellipse(0.4, 0.3, 4e-4, 0, 1e-4);
  EXPECT_NEAR(e.a, std::sqrt(5.991464547107979 * 4e-4), 1e-12);
  EXPECT_NEAR(e.b, std::sqrt(5.991464547107979 * 1e-4), 1e-12);
  EXPECT_NEAR(e.angle_rad, 0.0, 1e-12);
  // Rotated by 30 degrees: C = R diag(4, 1) R^T * 1e-4.
  double c = std::cos(kPiT / 6), s = std::sin(kPiT / 6);
  Ellipse r = covariance_ellipse(0, 0, 1e-4 * (4 * c * c + s * s), 1e-4 * 3 * c * s, 1e-4 * (4 * s * s + c * c));
  EXPECT_NEAR(r.a, e.a, 1e-12);
  EXPECT_NEAR(r.b, e.b, 1e-12);
  EXPECT_NEAR(r.angle_rad, kPiT / 6, 1e-12);
  // 5.991 is the 95 % point of chi-square with 2 degrees of freedom: 1 - exp(-x / 2) = 0.95.
  EXPECT_NEAR(1 - std::exp(-kChiSquare2Dof95 / 2), 0.95, 1e-12);
}

TEST(Chroma, UnchangedWhenTheRadianceIsScaledWithoutNoise) {
  CameraDescription cam = load_camera(kOralEye);
  cam.noise = false;
  cam.sensor.dark_current_e_per_s = 0;  // a constant dark signal would not scale
  cam.sensor.bit_depth = 16;
  cam.sensor.system_gain_dn_per_e = 0.5;  // thousands of DN per cell: quantisation below 1e-4 in r, g
  cam.sensor.full_well_e = 1e7;
  ChartOptions o = small_chart_options();
  o.shading_corner = 0.3;  // strongly non-uniform light across the chart
  SpectralImage img = make_fluorescence_chart(o);
  CameraRunOptions opt;
  CameraRun a = simulate_camera(img, cam, opt, "chart");
  SpectralImage bright = img;
  for (auto& v : bright.data) v *= 4.0f;
  CameraRun b = simulate_camera(bright, cam, opt, "chart x4");
  const int black = cam.sensor.black_level_dn, white = cam.sensor.white_level_dn();
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col) {
      Roi roi{col * 16 + 2, row * 16 + 2, 12, 12};
      ChromaStats sa = roi_chromaticity(a.raw.dn, img.width, img.height, cam.sensor.cfa, black, white, roi);
      ChromaStats sb = roi_chromaticity(b.raw.dn, img.width, img.height, cam.sensor.cfa, black, white, roi);
      ASSERT_EQ(sa.used, 36u);
      // Quantisation (+-0.5 DN in cells of a thousand DN and more) is all that may differ.
      EXPECT_NEAR(sa.mean_r, sb.mean_r, 5e-4) << row << "," << col;
      EXPECT_NEAR(sa.mean_g, sb.mean_g, 5e-4) << row << "," << col;
      EXPECT_EQ(sb.saturated, 0u);
    }
  // The expected electrons themselves scale exactly.
  for (size_t i = 0; i < a.expected.channel_e.size(); i += 3) {
    double sa = a.expected.channel_e[i] + a.expected.channel_e[i + 1] + a.expected.channel_e[i + 2];
    double sb = b.expected.channel_e[i] + b.expected.channel_e[i + 1] + b.expected.channel_e[i + 2];
    ASSERT_NEAR(a.expected.channel_e[i] / sa, b.expected.channel_e[i] / sb, 1e-6);
  }
}

TEST(Chroma, SmoothShadingKeepsChromaticityButTiltedFiltersMoveIt) {
  // One large FAD patch, light falling to 30 % at the corners. With filters that do not shift the
  // cells' chromaticity hardly spreads; with interference filters (40 deg field of view) the corners
  // see a bluer long-pass edge and the spread grows: the effect the product exists to expose.
  ChartOptions o = small_chart_options();
  o.fluorophores = {"FAD"};
  o.concentrations = {2e-3};
  o.patch_px = 256;
  o.shading_corner = 0.5;
  SpectralImage img = make_fluorescence_chart(o);
  CameraDescription cam = load_camera(kOralEye);
  cam.noise = false;
  cam.sensor.dark_current_e_per_s = 0;
  cam.sensor.bit_depth = 16;
  cam.sensor.system_gain_dn_per_e = 2.0;
  cam.sensor.full_well_e = 1e7;
  auto spread = [&](bool interference) {
    CameraDescription c = cam;
    for (auto& f : c.filters.filters) f.filter.interference = interference;
    CameraRun r = simulate_camera(img, c, {}, "patch");
    return roi_chromaticity(r.raw.dn, img.width, img.height, c.sensor.cfa, c.sensor.black_level_dn,
                            c.sensor.white_level_dn(), {0, 0, 256, 256});
  };
  ChromaStats flat = spread(false), tilted = spread(true);
  EXPECT_LT(flat.ellipse95.a, 3e-3);
  EXPECT_GT(tilted.ellipse95.a, 3 * flat.ellipse95.a);
  RecordProperty("ellipse_a_no_shift", std::to_string(flat.ellipse95.a));
  RecordProperty("ellipse_a_interference", std::to_string(tilted.ellipse95.a));
}

TEST(Chroma, EveryReferenceLineStartsAtTheTongueReflectancePoint) {
  CameraDescription cam = box_camera();
  cam.filters.filters.push_back({OpticalFilter{}, FilterPosition::kFrontOfLens});  // 475 nm long-pass, OD 4
  Spectrum led = gaussian_spectrum(405, 15);
  Spectrum refl = tongue_reflectance_spectrum();
  ReferenceOptions ro;
  ReferenceSetup setup = make_reference_setup(cam, led, refl, ro);
  // Independent tongue point: S_k = integral R E lambda T QE_k d lambda at 0.01 nm.
  double S[3] = {0, 0, 0};
  for (double nm = 300.005; nm < 800; nm += 0.01) {
    double base = refl(nm) * led(nm) * nm * cam.filters.transmittance(nm) * 0.01;
    for (int k = 0; k < 3; ++k) S[k] += base * cam.sensor.qe[k](nm);
  }
  double r0 = S[0] / (S[0] + S[1] + S[2]), g0 = S[1] / (S[0] + S[1] + S[2]);
  auto lib = fluorophore_library();
  ASSERT_GE(lib.size(), 5u);
  for (const auto& f : lib) {
    GridEem eem = load_fluorophore(f.name, setup.grid);
    ReferenceLine line = reference_line(setup, f.name, eem);
    ASSERT_FALSE(line.rg.empty());
    EXPECT_EQ(line.concentration.front(), 0.0);
    EXPECT_NEAR(line.rg.front()[0], r0, 2e-3) << f.name;
    EXPECT_NEAR(line.rg.front()[1], g0, 2e-3) << f.name;
    if (!line.visible) continue;
    // Along the line the chromaticity moves steadily away from the tongue toward the fluorophore.
    double prev = -1;
    for (auto& p : line.rg) {
      double d = std::hypot(p[0] - line.rg.front()[0], p[1] - line.rg.front()[1]);
      EXPECT_GE(d, prev - 1e-12) << f.name;
      prev = d;
    }
    double to_pure = std::hypot(line.rg.back()[0] - line.pure_rg[0], line.rg.back()[1] - line.pure_rg[1]);
    double span = std::hypot(line.pure_rg[0] - r0, line.pure_rg[1] - g0);
    EXPECT_LT(to_pure, 0.02 * span) << f.name;
  }
}

TEST(Chroma, ChartPatchLiesOnItsReferenceLine) {
  // The camera simulation of a tongue + FAD patch and the reference-line construction are two
  // different computations of the same thing: they must agree.
  CameraDescription cam = load_camera(kOralEye);
  cam.noise = false;
  cam.sensor.dark_current_e_per_s = 0;
  cam.sensor.bit_depth = 16;
  cam.sensor.system_gain_dn_per_e = 2.0;
  cam.sensor.full_well_e = 1e7;
  ChartOptions o = small_chart_options();
  // Uniform light and a realistic pixel size (0.16 deg): a light or filter-angle gradient across a
  // 2x2 cell biases its r, g (each colour is sampled at a different place).
  // 5 nm bands: with 10 nm bands the reflected LED tail across the 475 nm edge is spread evenly
  // over its band, which moves the tongue point by ~0.004 in r (docs/camera.md).
  o.shading_corner = 1.0;
  o.patch_px = 80;
  o.band_nm = bands(400, 700, 5);
  SpectralImage img = make_fluorescence_chart(o);
  CameraRun run = simulate_camera(img, cam, {}, "chart");
  ReferenceOptions ro;
  ro.camera_lo_nm = img.band_lo().front();
  ro.camera_hi_nm = img.band_hi().back();
  for (int col = 0; col < 3; ++col) {
    Roi roi{col * 80 + 36, 36, 8, 8};  // FAD row, the patch centre
    double r_px = std::hypot(roi.x + 4 - 0.5 * img.width, roi.y + 4 - 0.5 * img.height);
    ro.aoi_front_rad = run.geometry.field_angle(r_px);
    ro.aoi_sensor_rad = run.geometry.sensor_angle(r_px);
    ReferenceSetup setup = make_reference_setup(cam, o.led, o.reflectance, ro);
    GridEem fad = load_fluorophore("FAD", setup.grid);
    auto expect = reference_rg(setup, &fad, o.concentrations[col]);
    ChromaStats s = roi_chromaticity(run.raw.dn, img.width, img.height, cam.sensor.cfa, cam.sensor.black_level_dn,
                                     cam.sensor.white_level_dn(), roi);
    EXPECT_NEAR(s.mean_r, expect[0], 3e-3) << "c = " << o.concentrations[col];
    EXPECT_NEAR(s.mean_g, expect[1], 3e-3) << "c = " << o.concentrations[col];
  }
}

TEST(Chroma, CliWritesPlotAndLinesFromTheSidecar) {
  auto dir = scratch("chroma_cli");
  auto exr = dir / "chart.exr";
  write_spectral_exr(exr, make_fluorescence_chart(small_chart_options()));
  auto out = dir / "out";
  ASSERT_EQ(run_oralfluor("camera " + exr.string() + " --camera " + kOralEye + " -o " + out.string(), dir).exit_code, 0);
  CommandResult r = run_oralfluor("chroma " + (out / "raw.tiff").string() + " --roi 18,2,12,12 --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["stats"]["cells_used"], 36);
  EXPECT_EQ(j["lines"].size(), fluorophore_library().size());
  for (auto& l : j["lines"]) {
    EXPECT_EQ(l["concentration"][0], 0.0);
    EXPECT_EQ(l["rg"][0], j["reference"]["tongue_rg"]) << l["fluorophore"];
  }
  EXPECT_EQ(j["reference"]["led"], "oralfluor.excitation_spd of the radiance EXR");
  for (const char* f : {"chroma.svg", "chroma.png", "chroma.json", "chroma_cells.csv"})
    EXPECT_TRUE(std::filesystem::is_regular_file(out / f)) << f;
  std::ifstream svg(out / "chroma.svg");
  std::string text((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.rfind("<svg", 0), 0u);
  EXPECT_NE(text.find("protoporphyrin"), std::string::npos);
  auto png = OIIO::ImageInput::open((out / "chroma.png").string());
  ASSERT_TRUE(png);
  EXPECT_EQ(png->spec().width, 1480);
}
