// Sweep metrics on synthetic inputs with known answers: percentiles and CV of a known irradiance
// field, the 95 % ellipse area of a known covariance, per-cell chromaticity equal to `oralfluor
// chroma`'s, the fluorescence / reflected / leaked-excitation split against a closed-form filter
// integral, the LED band, the EMVA SNR against a simulated flat field, lesion contrast.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "renderer/analysis/chromaticity.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/sensor/sensor_model.h"
#include "renderer/sweep/metrics/signal_split.h"
#include "renderer/sweep/metrics/sweep_metrics.h"

using namespace ofl;

namespace {
constexpr double kPi = 3.14159265358979323846;

// A camera read through the camera.json parser: box QEs (B 400-500 nm 0.4, G 500-600 nm 0.5,
// R 600-700 nm 0.6), a measured absorbing long-pass with T = 0.01 below 470 nm and 0.9 above 480 nm.
CameraDescription box_camera_with_longpass() {
  auto box = [](double a, double b, double v) {
    return nlohmann::json{{"type", "points"}, {"points", {{a, v}, {b, v}}}, {"outside", "zero"}};
  };
  nlohmann::json j = {
      {"lens", {{"f_number", 2.8}, {"cos4", false}}},
      {"filters", {{{"type", "measured"}, {"points", {{300, 0.01}, {470, 0.01}, {480, 0.9}, {900, 0.9}}}, {"interference", false}}}},
      {"sensor", {{"pixel_pitch_um", 3.0}, {"qe", {{"R", box(600, 700, 0.6)}, {"G", box(500, 600, 0.5)}, {"B", box(400, 500, 0.4)}}},
                  {"exposure_s", 0.01}, {"system_gain_dn_per_e", 0.25}, {"full_well_e", 1e9}, {"bit_depth", 16}}},
      {"noise", false}};
  return parse_camera(JsonFile::from(j, "box_camera.json").root());
}

std::vector<double> bands(double lo, double hi, double step) {
  std::vector<double> b;
  for (double nm = lo; nm <= hi + 1e-9; nm += step) b.push_back(nm);
  return b;
}
}  // namespace

TEST(SweepMetrics, IrradianceStatisticsOfAKnownField) {
  // Pixels 1..100 W/m^2 in the mask, a bright pixel outside it that must not count.
  std::vector<float> irr;
  std::vector<uint8_t> mask;
  for (int i = 1; i <= 100; ++i) {
    irr.push_back(float(i));
    mask.push_back(1);
  }
  irr.push_back(1e6f);
  mask.push_back(0);
  IrradianceStats s = irradiance_stats(irr, mask);
  EXPECT_EQ(s.pixels, 100u);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.min_over_max, 0.01);
  // Type-7 percentiles: h = p (n - 1); 5 %: 4.95 -> 5 + 0.95; 95 %: 94.05 -> 95 + 0.05.
  EXPECT_NEAR(s.p5, 5.95, 1e-12);
  EXPECT_NEAR(s.p95, 95.05, 1e-12);
  EXPECT_NEAR(s.p5_over_p95, 5.95 / 95.05, 1e-12);
  // Sample std of 1..n is sqrt(n (n + 1) / 12).
  EXPECT_NEAR(s.cv, std::sqrt(100.0 * 101.0 / 12.0) / 50.5, 1e-12);
  // A uniform field: CV 0, ratios 1.
  IrradianceStats u = irradiance_stats(std::vector<float>(10, 3.0f), std::vector<uint8_t>(10, 1));
  EXPECT_DOUBLE_EQ(u.cv, 0.0);
  EXPECT_DOUBLE_EQ(u.p5_over_p95, 1.0);
}

TEST(SweepMetrics, EllipseAreaOfAKnownCovariance) {
  // Four points (+-a, 0), (0, +-b) around (0.3, 0.4): sample covariance diag(2a^2/3, 2b^2/3).
  double a = 0.03, b = 0.01;
  std::vector<std::array<double, 2>> rg = {{0.3 + a, 0.4}, {0.3 - a, 0.4}, {0.3, 0.4 + b}, {0.3, 0.4 - b}};
  Spread s = chroma_spread(rg);
  EXPECT_NEAR(s.std_r, std::sqrt(2 * a * a / 3), 1e-15);
  EXPECT_NEAR(s.std_g, std::sqrt(2 * b * b / 3), 1e-15);
  EXPECT_NEAR(s.area, kPi * 5.991464547107979 * (2 * a * b / 3), 1e-15);
  // The same covariance rotated by 30 degrees has the same area.
  double c = std::cos(kPi / 6), sn = std::sin(kPi / 6);
  std::vector<std::array<double, 2>> rot;
  for (auto& p : rg) {
    double x = p[0] - 0.3, y = p[1] - 0.4;
    rot.push_back({0.3 + c * x - sn * y, 0.4 + sn * x + c * y});
  }
  EXPECT_NEAR(chroma_spread(rot).area, s.area, 1e-15);
  EXPECT_NEAR(ellipse_area(4e-4, 0, 1e-4), kPi * 5.991464547107979 * 2e-4, 1e-18);
}

TEST(SweepMetrics, CorrelationSlopeAndPercentileBasics) {
  std::vector<double> x = {1, 2, 3, 4, 5}, y = {3, 5, 7, 9, 11}, z = {11, 9, 7, 5, 3};
  EXPECT_NEAR(pearson(x, y), 1.0, 1e-15);
  EXPECT_NEAR(pearson(x, z), -1.0, 1e-15);
  EXPECT_NEAR(ls_slope(x, y), 2.0, 1e-15);
  EXPECT_TRUE(std::isnan(pearson(x, std::vector<double>(5, 1.0))));  // no variation: undefined
  EXPECT_DOUBLE_EQ(percentile({3, 1, 2}, 0.5), 2.0);
}

TEST(SweepMetrics, CellsAgreeWithOralfluorChroma) {
  // A 6x4 RGGB mosaic with varying values; all cells in the mask but the last column pair.
  int w = 6, h = 4;
  std::vector<uint16_t> dn(w * h);
  std::vector<float> e(w * h), irr(w * h, 1.0f);
  for (int i = 0; i < w * h; ++i) {
    dn[i] = uint16_t(100 + (i * 37) % 211);
    e[i] = float(dn[i] - 64) * 4.0f;  // expected electrons proportional to DN above black
  }
  std::vector<uint8_t> mask(w * h, 1);
  for (int y = 0; y < h; ++y) mask[y * w + 5] = 0;
  MetricImages im;
  im.width = w;
  im.height = h;
  im.cfa = CfaPattern::kRGGB;
  im.black = 64;
  im.white = 4095;
  im.raw = &dn;
  im.expected = &e;
  im.irradiance = &irr;
  RoiCells cells = roi_cells(im, mask);
  ChromaStats ref = roi_chromaticity(dn, w, h, CfaPattern::kRGGB, 64, 4095, {0, 0, w, h}, false, &mask);
  ASSERT_EQ(cells.cells.size(), ref.used);
  ASSERT_EQ(cells.cells.size(), 4u);  // 2 cell rows x 2 cell columns (the third column is masked)
  for (size_t k = 0; k < ref.rg.size(); ++k) {
    EXPECT_NEAR(cells.cells[k].rg[0], ref.rg[k][0], 1e-15);
    EXPECT_NEAR(cells.cells[k].rg[1], ref.rg[k][1], 1e-15);
    // Noise-free chromaticity from electrons proportional to DN above black is the same.
    EXPECT_NEAR(cells.cells[k].rg_nf[0], ref.rg[k][0], 1e-6);
  }
  Spread s = chroma_spread([&] {
    std::vector<std::array<double, 2>> v;
    for (auto& c : cells.cells) v.push_back(c.rg);
    return v;
  }());
  EXPECT_NEAR(s.cov_rr, ref.cov_rr, 1e-15);
  EXPECT_NEAR(s.cov_rg, ref.cov_rg, 1e-15);
  EXPECT_NEAR(s.area, kPi * ref.ellipse95.a * ref.ellipse95.b, 1e-12);
}

TEST(SweepMetrics, LedBandIsWhereTheSpectrumReachesTheThreshold) {
  // A Gaussian line at 405 nm, FWHM 10 nm, sampled on a 5 nm grid: it stays above 1e-3 of its peak
  // within 10 sqrt(ln 1000 / (4 ln 2)) = 15.8 nm, i.e. at grid points 390..420 nm.
  WavelengthGrid g{350, 800, 5};
  std::vector<double> led(g.size());
  for (int i = 0; i < g.size(); ++i) led[i] = std::exp(-4 * std::log(2.0) * std::pow((g.wavelength(i) - 405) / 10, 2));
  SpectralImage img;
  img.resize(1, 1, bands(370, 450, 10));  // bands [365,375], [375,385], ..., [445,455]
  auto in = led_band_mask(img.band_lo(), img.band_hi(), g, led, 1e-3);
  std::vector<bool> want = {false, false, true, true, true, true, false, false, false};  // centres 370..450
  EXPECT_EQ(in, want);
}

TEST(SweepMetrics, SignalSplitMatchesTheClosedFormFilterIntegral) {
  // Every pixel: reflected LED light L1 in the 430 nm band (inside the LED's band), fluorescence L2
  // in the 520 nm band and reflected light L3 (out of the LED band) in the 550 nm band.
  CameraDescription cam = box_camera_with_longpass();
  const int w = 8, h = 6;
  SpectralImage img;
  img.resize(w, h, bands(400, 700, 10));
  img.fluorescence.assign(img.data.size(), 0.0f);
  const double L1 = 100, L2 = 1, L3 = 0.2;
  auto band_index = [&](double nm) { return int(std::lround((nm - 400) / 10)); };
  for (int p = 0; p < w * h; ++p) {
    float* px = img.data.data() + size_t(p) * img.bands();
    px[band_index(430)] = float(L1);
    px[band_index(520)] = float(L2);
    px[band_index(550)] = float(L3);
    img.fluorescence[size_t(p) * img.bands() + band_index(520)] = float(L2);
  }
  std::vector<bool> in_band(img.bands(), false);
  for (double nm : {420.0, 430.0, 440.0}) in_band[band_index(nm)] = true;
  std::vector<std::string> warn;
  FieldGeometry g = make_field_geometry(cam.lens, cam.sensor, w, h, std::nullopt, &warn);
  SignalSplit sp = split_signal(img, in_band, cam, g);
  // Linearity: the parts add up to the camera's signal of the whole image.
  ExpectedSignal whole = expected_electrons(img, cam, g);
  for (size_t i = 0; i < whole.mosaic_e.size(); ++i)
    EXPECT_NEAR(sp.fluorescence[i] + sp.reflected[i] + sp.leak[i], whole.mosaic_e[i], 1e-5 * whole.mosaic_e[i] + 1e-9);

  std::vector<float> irr(w * h, 1.0f);
  std::vector<uint16_t> raw(w * h, 1000);
  MetricImages im;
  im.width = w;
  im.height = h;
  im.cfa = cam.sensor.cfa;
  im.black = 64;
  im.white = 65535;
  im.raw = &raw;
  im.expected = &whole.mosaic_e;
  im.irradiance = &irr;
  im.fluorescence = &sp.fluorescence;
  im.reflected = &sp.reflected;
  im.leak = &sp.leak;
  auto m = roi_metrics(im, std::vector<uint8_t>(w * h, 1), cam.sensor);
  // Closed form: electrons per pixel are proportional to L * T * QE * integral of lambda over the
  // band (photons per joule); B pixels (1/4) see the 430 nm band, G pixels (1/2) the others.
  double leak = 0.25 * L1 * 0.01 * 0.4 * (435.0 * 435 - 425.0 * 425) / 2;
  double fl = 0.5 * L2 * 0.9 * 0.5 * (525.0 * 525 - 515.0 * 515) / 2;
  double refl = 0.5 * L3 * 0.9 * 0.5 * (555.0 * 555 - 545.0 * 545) / 2;
  double total = leak + fl + refl;
  EXPECT_NEAR(m["share_leak"].get<double>(), leak / total, 1e-6);
  EXPECT_NEAR(m["share_fluorescence"].get<double>(), fl / total, 1e-6);
  EXPECT_NEAR(m["share_reflected"].get<double>(), refl / total, 1e-6);
  EXPECT_NEAR(m["share_leak"].get<double>() + m["share_fluorescence"].get<double>() + m["share_reflected"].get<double>(), 1.0,
              1e-12);
}

TEST(SweepMetrics, EmvaSnrByHandAndAgainstASimulatedFlatField) {
  SensorDescription s;
  s.read_noise_e = 10;
  s.dark_current_e_per_s = 0;
  s.dsnu_e = 0;
  s.prnu = 0;
  s.system_gain_dn_per_e = 0.5;
  s.exposure_s = 0.01;
  // 1000 e- shot + 100 e-^2 read + 1 / (12 K^2) quantisation.
  EXPECT_NEAR(emva_snr(1000, s), 1000 / std::sqrt(1000 + 100 + 1 / (12 * 0.25)), 1e-12);

  // The camera's own noise simulation of a flat field: its spatial variance in one frame holds
  // shot, dark shot, read, DSNU, PRNU and quantisation noise, as the model says.
  s.read_noise_e = 6;
  s.dark_current_e_per_s = 2000;  // 20 e- dark signal
  s.dsnu_e = 4;
  s.prnu = 0.02;
  s.system_gain_dn_per_e = 0.3;
  s.full_well_e = 1e6;
  s.bit_depth = 16;
  s.black_level_dn = 100;
  const int w = 256, h = 256;
  const double mu = 3000;
  std::vector<float> mosaic(w * h, float(mu));
  RawFrame f = simulate_raw(mosaic, w, h, s, true, 7, make_fixed_pattern(s, w, h));
  double sum = 0, sum2 = 0;
  for (uint16_t v : f.dn) {
    double e = (v - s.black_level_dn) / s.total_gain();
    sum += e;
    sum2 += e * e;
  }
  double n = double(f.dn.size()), mean = sum / n, var = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, mu + 20, 1.0);
  double model = emva_noise_e(mu, s);
  EXPECT_NEAR(std::sqrt(var) / model, 1.0, 0.02);  // 65 536 pixels: the std is known to ~0.3 %
}

TEST(SweepMetrics, LesionContrastDistanceAndMahalanobis) {
  double sgm = 0.01, d = 0.02;
  auto cluster = [&](double r, double g) {
    return std::vector<std::array<double, 2>>{{r + sgm, g}, {r - sgm, g}, {r, g + sgm}, {r, g - sgm}};
  };
  LesionContrast c = lesion_contrast(cluster(0.3 + d, 0.4), cluster(0.3, 0.4));
  EXPECT_NEAR(c.distance, d, 1e-15);
  // Pooled covariance diag(2 s^2 / 3): the distance in units of the spread along r.
  EXPECT_NEAR(c.mahalanobis, d / std::sqrt(2 * sgm * sgm / 3), 1e-9);
  LesionContrast diag = lesion_contrast(cluster(0.3 + d, 0.4 + d), cluster(0.3, 0.4));
  EXPECT_NEAR(diag.distance, d * std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(diag.mahalanobis, d * std::sqrt(2.0) / std::sqrt(2 * sgm * sgm / 3), 1e-9);
}

TEST(SweepMetrics, TwoRendersSeparateMonteCarloNoiseFromTheSpreadOfTheLight) {
  // A true chromaticity gradient (r rises across the image) seen through two independent noisy
  // "renders"; the metrics use their mean and recover both the noise and the true spread.
  const int w = 200, h = 200;
  std::vector<float> truth(size_t(w) * h * 3), a(truth.size()), b(truth.size()), mean(truth.size());
  std::mt19937 gen(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sigma = 0.05;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t p = size_t(y) * w + x;
      double t[3] = {100.0 + 60.0 * x / w, 200.0, 100.0};
      for (int c = 0; c < 3; ++c) {
        truth[p * 3 + c] = float(t[c]);
        a[p * 3 + c] = float(t[c] * (1 + sigma * n01(gen)));
        b[p * 3 + c] = float(t[c] * (1 + sigma * n01(gen)));
        mean[p * 3 + c] = 0.5f * (a[p * 3 + c] + b[p * 3 + c]);
      }
    }
  std::vector<float> mosaic(size_t(w) * h), irr(size_t(w) * h, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) mosaic[size_t(y) * w + x] = mean[(size_t(y) * w + x) * 3 + cfa_channel(CfaPattern::kRGGB, x, y)];
  MetricImages im;
  im.width = w;
  im.height = h;
  im.expected = &mosaic;
  im.channel_e = &mean;
  im.channel_e_a = &a;
  im.channel_e_b = &b;
  im.irradiance = &irr;
  SensorDescription s;
  RoiCells cells;
  auto m = roi_metrics(im, std::vector<uint8_t>(size_t(w) * h, 1), s, &cells);
  ASSERT_EQ(cells.cells.size(), size_t(w / 2) * (h / 2));
  // Direct answers from the truth: the spread of the true r over the cells, and the error of the
  // analysed (mean) image's r.
  std::vector<double> r_true, r_err, g_true;
  for (auto& c : cells.cells) {
    double t[3] = {0, 0, 0};
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        for (int k = 0; k < 3; ++k) t[k] += truth[((size_t(c.y) + dy) * w + c.x + dx) * 3 + k] / 4.0;
    double rt = t[0] / (t[0] + t[1] + t[2]);
    r_true.push_back(rt);
    g_true.push_back(t[1] / (t[0] + t[1] + t[2]));
    r_err.push_back(c.rg_nf[0] - rt);
  }
  EXPECT_NEAR(m["r_std_mc"].get<double>() / std_of(r_err), 1.0, 0.05);
  EXPECT_NEAR(m["r_std_light"].get<double>() / std_of(r_true), 1.0, 0.05);
  EXPECT_GT(m["r_std_nf"].get<double>(), m["r_std_light"].get<double>());
  EXPECT_NEAR(m["g_std_light"].get<double>() / std_of(g_true), 1.0, 0.05);
}

TEST(SweepMetrics, ChromaticitySlopeAgainstFieldAngle) {
  // r = (100 + a theta) / 400 and g = (200 - a theta) / 400 exactly, theta = x degrees: the slopes
  // per 10 degrees are +-10 a / 400.
  const int w = 40, h = 4;
  const double a = 0.8;
  std::vector<float> ch(size_t(w) * h * 3), mosaic(size_t(w) * h), angle(size_t(w) * h), irr(size_t(w) * h, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      size_t p = size_t(y) * w + x;
      angle[p] = float(x);
      ch[p * 3 + 0] = float(100 + a * x);
      ch[p * 3 + 1] = float(200 - a * x);
      ch[p * 3 + 2] = 100.0f;
      mosaic[p] = ch[p * 3 + cfa_channel(CfaPattern::kRGGB, x, y)];
    }
  MetricImages im;
  im.width = w;
  im.height = h;
  im.expected = &mosaic;
  im.channel_e = &ch;
  im.irradiance = &irr;
  im.field_angle_deg = &angle;
  auto m = roi_metrics(im, std::vector<uint8_t>(size_t(w) * h, 1), SensorDescription{});
  EXPECT_NEAR(m["slope_r_angle"].get<double>(), 10 * a / 400, 1e-9);
  EXPECT_NEAR(m["slope_g_angle"].get<double>(), -10 * a / 400, 1e-9);
  EXPECT_TRUE(m["slope_r_irr"].is_null());  // uniform light: no slope against it
}
