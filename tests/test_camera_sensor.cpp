// Camera sensor model: closed-form electrons for a uniform radiance, EMVA 1288 order of operations
// and clipping, CFA phase, determinism across thread counts, the Poisson sampler.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

#include "camera_test_util.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/sensor/pixel_rng.h"
#include "renderer/camera/sensor/sensor_model.h"

using namespace ofl;
using namespace ofl::testing;

namespace {
// Independent closed form: electrons of a channel whose QE is q on [a, b] nm under a flat radiance
// L (W sr^-1 m^-2 nm^-1):  t A fill * pi T / (1 + 4 N^2 (1 - m)^2) * L * q * (b^2 - a^2) / 2 * 1e-9 / (h c).
double closed_form_electrons(double t, double pitch_um, double fill, double T, double N, double m, double L, double q,
                             double a, double b) {
  const double h = 6.62607015e-34, c = 299792458.0, pi = 3.14159265358979323846;
  double area = pitch_um * 1e-6 * pitch_um * 1e-6;
  double E_per_L = pi * T / (1.0 + 4.0 * N * N * (1.0 - m) * (1.0 - m));
  return t * area * fill * E_per_L * L * q * 0.5 * (b * b - a * a) * 1e-9 / (h * c);
}
}  // namespace

TEST(CameraSensor, UniformRadianceRawMeansEqualClosedFormTimesGain) {
  CameraDescription cam = box_camera();
  cam.lens.f_number = 2.8;
  cam.lens.magnification = -0.1;
  cam.lens.transmittance = constant_spectrum(0.9);
  cam.sensor.fill_factor = 0.8;
  cam.sensor.analog_gain = 2.0;
  cam.sensor.read_noise_e = 3.0;
  cam.sensor.dark_current_e_per_s = 100;  // at 25 C; 31 C with 6 C doubling -> 200 e-/s -> 2 e- in 10 ms
  cam.sensor.temperature_C = 31;
  cam.sensor.dark_doubling_C = 6;
  const double L = 0.05;
  SpectralImage img = uniform_image(128, 128, bands(400, 700, 10), L);
  const double expect[3] = {
      closed_form_electrons(0.01, 3.0, 0.8, 0.9, 2.8, -0.1, L, 0.6, 600, 700),
      closed_form_electrons(0.01, 3.0, 0.8, 0.9, 2.8, -0.1, L, 0.5, 500, 600),
      closed_form_electrons(0.01, 3.0, 0.8, 0.9, 2.8, -0.1, L, 0.4, 400, 500)};
  const double dark = 2.0, K = 0.25 * 2.0;
  ASSERT_GT(expect[2], 1000.0);  // a signal the check is sensitive to

  // Noise off: expected electrons match to float precision, every raw value is the rounded formula.
  CameraRunOptions quiet;
  quiet.noise = false;
  CameraRun q = simulate_camera(img, cam, quiet, "uniform");
  EXPECT_NEAR(q.expected.dark_e, dark, 1e-12);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) {
      int c = cfa_channel(cam.sensor.cfa, x, y);
      size_t i = static_cast<size_t>(y) * 128 + x;
      EXPECT_NEAR(q.expected.mosaic_e[i] / expect[c], 1.0, 1e-6) << "channel " << c;
      EXPECT_EQ(q.raw.dn[i], static_cast<uint16_t>(std::floor(K * (expect[c] + dark) + 0.5) + 64));
    }

  // Noise on: per-channel raw means equal K (e + dark) + black within 4 standard errors.
  CameraRunOptions noisy;
  noisy.noise = true;
  noisy.seed = 7;
  CameraRun n = simulate_camera(img, cam, noisy, "uniform");
  double sum[3] = {0, 0, 0}, cnt[3] = {0, 0, 0};
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      int c = cfa_channel(cam.sensor.cfa, x, y);
      sum[c] += n.raw.dn[static_cast<size_t>(y) * 128 + x] - 64.0;
      cnt[c] += 1;
    }
  for (int c = 0; c < 3; ++c) {
    double mean = sum[c] / cnt[c];
    double sigma = std::sqrt(K * K * (expect[c] + dark + 9.0) + 1.0 / 12.0);
    EXPECT_NEAR(mean, K * (expect[c] + dark), 4.0 * sigma / std::sqrt(cnt[c])) << "channel " << c;
  }
}

TEST(CameraSensor, CfaPhaseOfEveryPattern) {
  // Expected colours of the 2x2 cell (x, y) = (0,0), (1,0), (0,1), (1,1), spelled out by hand.
  struct Case {
    const char* name;
    int c00, c10, c01, c11;
  } cases[] = {{"RGGB", kRed, kGreen, kGreen, kBlue},
               {"GRBG", kGreen, kRed, kBlue, kGreen},
               {"GBRG", kGreen, kBlue, kRed, kGreen},
               {"BGGR", kBlue, kGreen, kGreen, kRed}};
  for (const auto& cs : cases) {
    auto p = parse_cfa_name(cs.name);
    ASSERT_TRUE(p.has_value()) << cs.name;
    EXPECT_EQ(cfa_name(*p), cs.name);
    for (int oy = 0; oy < 6; oy += 2)
      for (int ox = 0; ox < 6; ox += 2) {
        EXPECT_EQ(cfa_channel(*p, ox, oy), cs.c00) << cs.name;
        EXPECT_EQ(cfa_channel(*p, ox + 1, oy), cs.c10) << cs.name;
        EXPECT_EQ(cfa_channel(*p, ox, oy + 1), cs.c01) << cs.name;
        EXPECT_EQ(cfa_channel(*p, ox + 1, oy + 1), cs.c11) << cs.name;
      }
    // Through the whole camera: box QEs make the three colours' signals distinct, so each raw value
    // tells which filter sits on that pixel.
    CameraDescription cam = box_camera();
    cam.sensor.cfa = *p;
    SpectralImage img = uniform_image(4, 4, bands(400, 700, 10), 0.05);
    CameraRunOptions o;
    o.noise = false;
    CameraRun r = simulate_camera(img, cam, o, "uniform");
    const int want[4] = {cs.c00, cs.c10, cs.c01, cs.c11};
    for (int k = 0; k < 4; ++k) {
      int x = k % 2, y = k / 2;
      uint16_t dn = r.raw.dn[static_cast<size_t>(y) * 4 + x];
      uint16_t expect = digitise(r.expected.channel_e[(static_cast<size_t>(y) * 4 + x) * 3 + want[k]], cam.sensor);
      EXPECT_EQ(dn, expect) << cs.name << " pixel " << x << "," << y;
      for (int other = 0; other < 3; ++other) {
        if (other != want[k]) {
          EXPECT_NE(dn, digitise(r.expected.channel_e[(static_cast<size_t>(y) * 4 + x) * 3 + other], cam.sensor));
        }
      }
    }
  }
  EXPECT_FALSE(parse_cfa_name("RGBG").has_value());
}

TEST(CameraSensor, ClippingOrderFullWellBeforeGainThenAdc) {
  SensorDescription s;
  s.full_well_e = 1000;
  s.system_gain_dn_per_e = 2.0;
  s.analog_gain = 1.0;
  s.bit_depth = 12;  // 4095
  s.black_level_dn = 10;
  // Full well clips the charge before the gain: 5000 e- -> 1000 e- -> 2000 DN + 10.
  EXPECT_EQ(digitise(5000, s), 2010);
  EXPECT_EQ(digitise(1000, s), 2010);
  EXPECT_EQ(digitise(999, s), 2008);
  EXPECT_EQ(s.white_level_dn(), 2010);
  // Quantisation rounds to nearest, then the black level is added.
  EXPECT_EQ(digitise(100.2, s), 210);
  EXPECT_EQ(digitise(100.3, s), 211);  // 200.6 -> 201
  // Negative charge (read noise around zero) is kept through the gain and clipped at 0 by the ADC.
  EXPECT_EQ(digitise(-2, s), 6);
  EXPECT_EQ(digitise(-100, s), 0);
  // With 4x analog gain the ADC saturates first: 600 e- -> 4800 + 10 -> 4095, below full well.
  s.analog_gain = 4.0;
  EXPECT_EQ(digitise(600, s), 4095);
  EXPECT_EQ(digitise(500, s), 4010);
  EXPECT_EQ(s.white_level_dn(), 4095);

  // simulate_raw reports which clip acted.
  std::vector<float> e = {500.f, 600.f, 1500.f, 10.f};
  RawFrame r = simulate_raw(e, 4, 1, s, false, 1, {});
  EXPECT_EQ(r.dn, (std::vector<uint16_t>{4010, 4095, 4095, 90}));
  EXPECT_EQ(r.full_well_clipped, 1u);  // 1500 e-
  EXPECT_EQ(r.adc_clipped, 1u);        // 600 e-
}

TEST(CameraSensor, SameSeedSameRawWhateverTheThreadCount) {
  CameraDescription cam = box_camera();
  cam.sensor.read_noise_e = 2;
  cam.sensor.dsnu_e = 1;
  cam.sensor.prnu = 0.01;
  cam.sensor.dark_current_e_per_s = 500;
  cam.noise = true;
  SpectralImage img = uniform_image(96, 64, bands(400, 700, 10), 0.02);
  auto run = [&](int threads, uint64_t seed) {
    tbb::global_control g(tbb::global_control::max_allowed_parallelism, threads);
    CameraRunOptions o;
    o.seed = seed;
    return simulate_camera(img, cam, o, "uniform").raw.dn;
  };
  auto a = run(1, 11), b = run(2, 11), c = run(2, 12);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

TEST(CameraSensor, DarkCurrentDoublesEveryDoublingInterval) {
  SensorDescription s;
  s.dark_current_e_per_s = 40;
  s.dark_reference_C = 20;
  s.dark_doubling_C = 7;
  s.exposure_s = 2;
  s.temperature_C = 20;
  EXPECT_DOUBLE_EQ(s.dark_electrons(), 80.0);
  s.temperature_C = 27;
  EXPECT_NEAR(s.dark_electrons(), 160.0, 1e-9);
  s.temperature_C = 13;
  EXPECT_NEAR(s.dark_electrons(), 40.0, 1e-9);
  // A dark frame's mean is K times the dark electrons above black.
  s.temperature_C = 34;  // 4x: 320 e-
  s.system_gain_dn_per_e = 0.5;
  s.read_noise_e = 2;
  s.bit_depth = 14;
  std::vector<float> zero(200 * 200, 0.0f);
  RawFrame f = simulate_raw(zero, 200, 200, s, true, 3, {});
  double mean = 0;
  for (auto v : f.dn) mean += v - s.black_level_dn;
  mean /= f.dn.size();
  EXPECT_NEAR(mean, 0.5 * 320.0, 4 * std::sqrt(0.25 * (320 + 4) + 1 / 12.0) / 200.0);
}

TEST(CameraSensor, PoissonSamplerHasPoissonMoments) {
  for (double mu : {0.7, 5.0, 11.9, 12.1, 40.0, 3000.0}) {
    double s1 = 0, s2 = 0, zeros = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      PixelRng rng(5, NoisePurpose::kTemporal, static_cast<uint64_t>(i));
      double k = static_cast<double>(rng.poisson(mu));
      s1 += k;
      s2 += k * k;
      zeros += k == 0;
    }
    double mean = s1 / n, var = s2 / n - mean * mean;
    EXPECT_NEAR(mean, mu, 5 * std::sqrt(mu / n)) << mu;
    EXPECT_NEAR(var / mu, 1.0, 5 * std::sqrt(2.0 / n) + 5 * std::sqrt(1.0 / (mu * n))) << mu;
    if (mu < 6) {
      EXPECT_NEAR(zeros / n, std::exp(-mu), 5 * std::sqrt(std::exp(-mu) / n)) << mu;
    }
  }
  EXPECT_NEAR(log_factorial(300), std::lgamma(301.0), 1e-9);
  EXPECT_NEAR(log_factorial(20), std::lgamma(21.0), 1e-12);
}
