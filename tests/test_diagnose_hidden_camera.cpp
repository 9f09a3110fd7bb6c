// Diagnose, hidden effects in camera data: the Macbeth chart under two blackbody lights, two
// captures per patch (shot and read noise of 400-pixel patch means, 0.3 % capture-to-capture
// illumination jitter), seen by the MT9V024 behind an IR-cut filter, with one hidden sensor
// effect of random magnitude. The tool must name it and recover its parameters within the stated
// tolerance; without a hidden effect it must not claim one.
#include <gtest/gtest.h>

#include "diagnose_hidden_util.h"
#include "sanitizer_scale.h"

using namespace ofl;

namespace {
Diagnosis run(const SyntheticCamera& s, std::unique_ptr<CameraProblem>& p) {
  p = std::make_unique<CameraProblem>(s.data, s.model);
  SelectionOptions o;
  o.group_columns = {"row"};
  o.replicate_columns = {"patch", "illuminant"};
  o.max_causes = 2;
  return diagnose(*p, o);
}
}  // namespace

class DiagnoseHiddenCamera : public ::testing::TestWithParam<std::string> {};

TEST_P(DiagnoseHiddenCamera, NamesTheCauseAndRecoversItsParameters) {
  for (uint64_t seed : test::sanitized_cases(std::vector<uint64_t>{21, 22}, 1)) {
    SyntheticCameraOptions o;
    o.seed = seed;
    o.effect = GetParam();
    SyntheticCamera s = make_synthetic_camera(o);
    std::unique_ptr<CameraProblem> p;
    Diagnosis d = run(s, p);
    HiddenOutcome h = judge_outcome(*p, d, s, GetParam());
    EXPECT_EQ(h.named, s.effect_id) << "seed " << seed << ": " << h.detail;
    EXPECT_TRUE(h.params_ok) << "seed " << seed << ": " << h.detail;
    EXPECT_EQ(h.causes, 1) << "seed " << seed << ": " << d.verdict;
  }
}

INSTANTIATE_TEST_SUITE_P(Causes, DiagnoseHiddenCamera,
                         ::testing::Values("channel_gain", "crosstalk", "offset", "nonlinearity", "qe_shift", "nir_leak"));

TEST(DiagnoseHiddenCameraNull, NoCauseClaimedWithoutAHiddenEffect) {
  // 12 null data sets (4 under sanitizers), at most one claim.
  int claims = 0;
  std::string what;
  std::vector<uint64_t> seeds;
  for (uint64_t seed = 201; seed <= 212; ++seed) seeds.push_back(seed);
  seeds = test::sanitized_cases(seeds, 4);
  for (uint64_t seed : seeds) {
    SyntheticCameraOptions o;
    o.seed = seed;
    SyntheticCamera s = make_synthetic_camera(o);
    std::unique_ptr<CameraProblem> p;
    Diagnosis d = run(s, p);
    if (!d.causes.empty()) {
      ++claims;
      what += " seed " + std::to_string(seed) + ": " + d.verdict;
    }
  }
  std::printf("[ null camera ] claims in %d of %zu data sets\n", claims, seeds.size());
  EXPECT_LE(claims, 1) << what;
}
