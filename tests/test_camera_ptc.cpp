// Photon transfer (EMVA 1288) on simulated flat fields: the analysis must recover the sensor
// parameters the simulation was given.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/camera/sensor/photon_transfer.h"
#include "renderer/camera/sensor/sensor_model.h"

using namespace ofl;

namespace {
struct FlatFields {
  SensorDescription s;
  int w = 256, h = 256;
  FixedPattern fp;
  uint64_t seed = 1000;
  explicit FlatFields(const SensorDescription& sensor) : s(sensor) { fp = make_fixed_pattern(s, w, h); }
  RawPixels frame(double mu) {
    std::vector<float> e(static_cast<size_t>(w) * h, static_cast<float>(mu));
    return simulate_raw(e, w, h, s, true, seed++, fp).dn;
  }
  FramePair pair(double mu) { return {frame(mu), frame(mu)}; }
};

SensorDescription test_sensor() {
  SensorDescription s;
  s.system_gain_dn_per_e = 0.35;
  s.read_noise_e = 4.0;
  s.full_well_e = 40000;
  s.bit_depth = 14;  // 40000 e- * 0.35 + 64 < 16383: the full well, not the ADC, saturates
  s.black_level_dn = 64;
  return s;
}
}  // namespace

TEST(PhotonTransfer, RecoversGainReadNoiseAndFullWellWithin3Percent) {
  SensorDescription s = test_sensor();
  s.dsnu_e = 2.0;  // fixed pattern cancels in the frame differences
  FlatFields ff(s);
  FramePair dark = ff.pair(0);
  std::vector<FramePair> series;
  for (int k = 1; k <= 60; ++k) series.push_back(ff.pair(s.full_well_e * 1.2 * k / 60));
  PhotonTransferResult r = analyse_photon_transfer(dark, series);
  EXPECT_GE(r.fit_points, 20);
  EXPECT_NEAR(r.system_gain_dn_per_e / s.system_gain_dn_per_e, 1.0, 0.03);
  EXPECT_NEAR(r.read_noise_e / s.read_noise_e, 1.0, 0.03);
  EXPECT_NEAR(r.saturation_capacity_e / s.full_well_e, 1.0, 0.03);
  EXPECT_NEAR(r.full_well_plateau_e / s.full_well_e, 1.0, 0.01);
  RecordProperty("K", std::to_string(r.system_gain_dn_per_e));
  RecordProperty("read_noise_e", std::to_string(r.read_noise_e));
  RecordProperty("saturation_capacity_e", std::to_string(r.saturation_capacity_e));
}

TEST(PhotonTransfer, PrnuPullsEmvaSaturationBelowFullWellButNotThePlateau) {
  // With 1 % PRNU the brightest pixels clip first, so the variance peaks early; the standard's
  // saturation capacity then reads low while the clipped plateau still gives the full well.
  SensorDescription s = test_sensor();
  s.prnu = 0.01;
  FlatFields ff(s);
  FramePair dark = ff.pair(0);
  std::vector<FramePair> series;
  for (int k = 1; k <= 60; ++k) series.push_back(ff.pair(s.full_well_e * 1.2 * k / 60));
  PhotonTransferResult r = analyse_photon_transfer(dark, series);
  EXPECT_NEAR(r.system_gain_dn_per_e / s.system_gain_dn_per_e, 1.0, 0.03);
  EXPECT_LT(r.saturation_capacity_e, 0.99 * s.full_well_e);
  EXPECT_GT(r.saturation_capacity_e, 0.93 * s.full_well_e);
  EXPECT_NEAR(r.full_well_plateau_e / s.full_well_e, 1.0, 0.01);
}

TEST(PhotonTransfer, DsnuAndPrnuFromFrameAverages) {
  SensorDescription s = test_sensor();
  s.dsnu_e = 3.0;
  s.prnu = 0.01;
  FlatFields ff(s);
  std::vector<RawPixels> dark, bright;
  for (int i = 0; i < 16; ++i) {
    dark.push_back(ff.frame(0));
    bright.push_back(ff.frame(0.5 * s.full_well_e));
  }
  NonUniformity u = analyse_nonuniformity(dark, bright, s.system_gain_dn_per_e);
  EXPECT_NEAR(u.dsnu_e / s.dsnu_e, 1.0, 0.03);
  EXPECT_NEAR(u.prnu / s.prnu, 1.0, 0.03);
  // Without fixed pattern both come out near zero (only the estimators' noise).
  SensorDescription clean = test_sensor();
  FlatFields fc(clean);
  std::vector<RawPixels> d2, b2;
  for (int i = 0; i < 16; ++i) {
    d2.push_back(fc.frame(0));
    b2.push_back(fc.frame(0.5 * clean.full_well_e));
  }
  NonUniformity z = analyse_nonuniformity(d2, b2, clean.system_gain_dn_per_e);
  EXPECT_LT(z.dsnu_e, 0.3);
  EXPECT_LT(z.prnu, 0.001);
}
