// Diagnose, hidden effects in spectra: synthetic spectroradiometer data (4 subjects x 2 sites x
// 3 LEDs x 2 locations, 1 % shot-like noise + 0.2 % floor, 5 % location-to-location composition
// jitter; made on a 1 nm grid, diagnosed on a 2 nm grid, so the fitted model is never exactly the
// generating one) from the baseline model plus one hidden cause of random magnitude. The tool must name
// that cause first and recover its parameter within the stated tolerance (synthetic.h); on data
// with no hidden cause it must not claim one.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "diagnose_hidden_util.h"
#include "sanitizer_scale.h"

using namespace ofl;

namespace {
Diagnosis run(const SyntheticSpectra& s, std::unique_ptr<SpectraProblem>& p) {
  p = std::make_unique<SpectraProblem>(s.data, s.model);
  SelectionOptions o;
  o.group_columns = {"subject"};
  o.replicate_columns = synthetic_spectra_replicates();
  o.max_causes = 2;  // the hidden cause, then one more step to show nothing else beats the noise
  return diagnose(*p, o);
}
}  // namespace

class DiagnoseHiddenSpectra : public ::testing::TestWithParam<std::string> {};

TEST_P(DiagnoseHiddenSpectra, NamesTheCauseAndRecoversItsParameter) {
  // Two random magnitudes per cause; for the extra fluorophore one case per candidate (elastin
  // and teeth lie within 2.5-7 % of the baseline fluorophores' span, the hardest cases). Under
  // sanitizers one case per cause (for the extra fluorophore the hardest, elastin).
  // Elastin and teeth change a spectrum by about 0.4 % on these data, below the noise floor: once
  // the model nearly fits, a tissue cause must explain at least the noise floor (instrument
  // mismatch rule, docs/diagnose.md 4.3), so they are not named; what is required of them is that
  // nothing else is named instead (DiagnoseHiddenSpectra.BelowTheFloorNothingWrongIsNamed).
  const bool extra = GetParam() == std::string("extra_fluorophore");
  const std::vector<uint64_t> seeds =
      test::sanitized_cases(extra ? std::vector<uint64_t>{11, 14} : std::vector<uint64_t>{11, 12}, 1);
  const std::map<uint64_t, const char*> extras = {{11, "chlorophyll_a"}, {14, "chlorophyll_a"}};
  for (size_t k = 0; k < seeds.size(); ++k) {
    const uint64_t seed = seeds[k];
    SyntheticSpectraOptions o;
    o.seed = seed;
    o.effect = GetParam();
    if (extra) o.extra_fluorophore = extras.at(seed);
    SyntheticSpectra s = make_synthetic_spectra(o);
    std::unique_ptr<SpectraProblem> p;
    Diagnosis d = run(s, p);
    HiddenOutcome h = judge_outcome(*p, d, s, GetParam());
    EXPECT_EQ(h.named, s.effect_id) << "seed " << seed << ": " << h.detail;
    EXPECT_TRUE(h.params_ok) << "seed " << seed << ": " << h.detail;
    EXPECT_EQ(h.causes, 1) << "seed " << seed << ": a second cause was claimed: " << d.verdict;
    EXPECT_LT(d.rmse_extended_heldout, d.rmse_baseline_heldout);
  }
}

TEST(DiagnoseHiddenSpectraWeak, BelowTheFloorNothingWrongIsNamed) {
  // Hidden elastin or tooth fluorescence, whose effect is below the noise floor: either it is named
  // (with nothing else) or nothing is; never another cause in its place.
  const std::map<uint64_t, const char*> extras = {{12, "elastin"}, {13, "teeth"}};
  for (auto [seed, name] : extras) {
    SyntheticSpectraOptions o;
    o.seed = seed;
    o.effect = "extra_fluorophore";
    o.extra_fluorophore = name;
    SyntheticSpectra s = make_synthetic_spectra(o);
    std::unique_ptr<SpectraProblem> p;
    Diagnosis d = run(s, p);
    HiddenOutcome h = judge_outcome(*p, d, s, "extra_fluorophore");
    EXPECT_TRUE(h.causes == 0 || (h.causes == 1 && h.named == s.effect_id)) << "seed " << seed << ": " << h.detail;
  }
}

INSTANTIATE_TEST_SUITE_P(Causes, DiagnoseHiddenSpectra,
                         ::testing::Values("blood_absorption", "extra_fluorophore", "wavelength_shift", "bandwidth",
                                           "emission_broadening", "stray_light", "longpass_leak", "longpass_edge"));

TEST(DiagnoseHiddenSpectraNull, NoCauseClaimedWithoutAHiddenEffect) {
  // 12 null data sets (4 under sanitizers). Claims allowed: at most 1 (observed in this test: 0;
  // the benchmark diagnose_hidden_effects states the rate over more seeds with its 95 % upper bound).
  int claims = 0;
  std::string what;
  std::vector<uint64_t> seeds;
  for (uint64_t seed = 101; seed <= 112; ++seed) seeds.push_back(seed);
  seeds = test::sanitized_cases(seeds, 4);
  for (uint64_t seed : seeds) {
    SyntheticSpectraOptions o;
    o.seed = seed;
    SyntheticSpectra s = make_synthetic_spectra(o);
    std::unique_ptr<SpectraProblem> p;
    Diagnosis d = run(s, p);
    if (!d.causes.empty()) {
      ++claims;
      what += " seed " + std::to_string(seed) + ": " + d.verdict;
    }
    if (d.causes.empty()) {
      EXPECT_EQ(d.verdict.rfind("no significant effect", 0), 0u) << d.verdict;
    }
  }
  std::printf("[ null spectra ] claims in %d of %zu data sets\n", claims, seeds.size());
  EXPECT_LE(claims, 1) << what;
}
