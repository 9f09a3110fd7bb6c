// Diagnose on data it did not make (tests/independent_spectra.h: own grids, own EEM interpolation
// and photon bookkeeping, point-sampled records). What it must show (docs/diagnose.md): an emission shift and an
// instrument-axis shift are separate causes; an emission shift is named with its value within
// 0.3 nm; an offset and an excitation leak are named alone with their sizes within 10 %;
// a band in no library spectrum is found with its peak within 5 nm; a cause carried by one subject
// is found in the pooled data and reported with that subject; null data get no tissue cause.
// Where a target of the issue is not met the test says so and asserts what is achieved.
#include <gtest/gtest.h>

#include "independent_spectra.h"
#include "renderer/diagnose/spectra/cross_subject.h"
#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/diagnose/spectra/unknown_band.h"

using namespace ofl;

namespace {

struct Outcome {
  std::unique_ptr<SpectraProblem> p;
  Diagnosis d;
  std::string first() const { return d.causes.empty() ? "" : p->candidates()[d.causes[0].candidate].id; }
  std::string all() const {
    std::string s = d.verdict + "\n";
    for (size_t k = 0; k < d.steps.size(); ++k)
      for (auto& t : d.steps[k])
        if (t.mean_gain > t.optimism)
          s += "  step " + std::to_string(k + 1) + " " + p->candidates()[t.candidate].id + " gain " + std::to_string(t.mean_gain) +
               " thr " + std::to_string(t.threshold) + " effect/floor " +
               std::to_string(std::sqrt(std::max(0.0, t.mean_gain - t.optimism)) / d.floor.rmse) + " " + t.verdict + "\n";
    return s;
  }
  double estimate(const std::string& q) const { return cause_estimate(*p, d.causes[0], q).value; }
};

Outcome diagnose_independent(const indep::Data& data, int max_causes = 2) {
  Outcome r;
  r.p = std::make_unique<SpectraProblem>(data.set, data.model);
  SelectionOptions o;
  o.group_columns = {"subject"};
  o.replicate_columns = {"subject", "site", "light_nm"};
  o.max_causes = max_causes;
  r.d = diagnose(*r.p, o);
  return r;
}

indep::Data make(const std::string& effect, uint64_t seed, double magnitude = NAN) {
  indep::Options o;
  o.effect = effect;
  o.seed = seed;
  o.magnitude = magnitude;
  return indep::make_independent(o);
}

}  // namespace

TEST(DiagnoseIndependent, EmissionShiftAndAxisShiftAreSeparateCauses) {
  // 1 nm (the smallest) is below the noise floor on data that nearly fit: named because it
  // predicts held-out data significantly better than every instrument cause (docs/diagnose.md 4.3);
  // before that rule it was missed in 5 of 10 benchmark runs.
  for (double m : {2.0, -1.5, 1.0}) {
    auto data = make("emission_shift", 21, m);
    Outcome r = diagnose_independent(data);
    EXPECT_EQ(r.first(), "emission_shift") << r.all();
    if (r.first() == "emission_shift") EXPECT_NEAR(r.estimate("delta_nm"), m, 0.3) << r.all();
  }
  // One fluorophore's shift is that fluorophore's, with its value.
  {
    auto data = make("emission_shift:FAD", 26, -3.0);
    Outcome r = diagnose_independent(data);
    EXPECT_EQ(r.first(), "emission_shift:FAD") << r.all();
    if (r.first() == "emission_shift:FAD") EXPECT_NEAR(r.estimate("delta_nm"), -3.0, 0.3) << r.all();
  }
  // The axis shift is named as such, not as an emission shift, with its value.
  auto data = make("wavelength_shift", 22, 1.5);
  Outcome r = diagnose_independent(data);
  EXPECT_EQ(r.first(), "wavelength_shift") << r.all();
  if (r.first() == "wavelength_shift") EXPECT_NEAR(r.estimate("delta_nm"), 1.5, 0.3) << r.all();
}

TEST(DiagnoseIndependent, OffsetIsNamedAloneAndItsSizeRecovered) {
  auto data = make("offset", 23, 0.04);
  Outcome r = diagnose_independent(data, 3);
  EXPECT_EQ(r.first(), "stray_light") << r.all();
  EXPECT_EQ(r.d.causes.size(), 1u) << r.all();
  // The generator's offset is a fraction of the signal before the offset; diagnose reports it as a
  // fraction of the mean of everything else it predicts (the same quantity).
  // Within the 10 %. (On a 2 nm model grid it was 0.029: the long-pass edge, interpolated
  // from a grid coarser than its transition, was made up for by the offset; docs/diagnose.md.)
  if (r.first() == "stray_light") EXPECT_NEAR(r.estimate("fraction"), 0.04, 0.004) << r.all();
}

TEST(DiagnoseIndependent, ExcitationLeakIsNamedAloneWithItsSize) {
  // Alone: on a 1 nm model grid an unknown band and an axis shift followed the leak, taking up the
  // leak's edge interpolated too coarsely (docs/diagnose.md "Model grid").
  auto data = make("excitation_leak", 24, 0.03);
  Outcome r = diagnose_independent(data, 3);
  EXPECT_EQ(r.first(), "longpass_leak") << r.all();
  EXPECT_EQ(r.d.causes.size(), 1u) << r.all();
  // 10 % in leaked radiance is 0.041 in optical density.
  if (r.first() == "longpass_leak") EXPECT_NEAR(r.estimate("effective_od"), data.truth.at("effective_od"), 0.0414) << r.all();
}

TEST(DiagnoseIndependent, ExcitationLeakIsNamedWithoutAMeasuredLeak) {
  // The model has no leak column ("leak": "none") and the data no white-target leak: the leak
  // candidate is the LED spectrum times the long-pass's blocked fraction. Before, there was no
  // candidate at all and leaked light could only be described by wrong causes.
  indep::Options o;
  o.effect = "excitation_leak";
  o.seed = 24;
  o.magnitude = 0.03;
  o.model_leak = "none";
  o.white_leak = 0;
  auto data = indep::make_independent(o);
  Outcome r = diagnose_independent(data, 3);
  EXPECT_EQ(r.first(), "longpass_leak") << r.all();
  EXPECT_EQ(r.d.causes.size(), 1u) << r.all();
  // 10 % in leaked radiance is 0.041 in optical density.
  if (r.first() == "longpass_leak") EXPECT_NEAR(r.estimate("effective_od"), data.truth.at("effective_od"), 0.0414) << r.all();
}

TEST(DiagnoseIndependent, ADetectorSideOffsetOfOneToEightPercentOfThePeakIsStrayLightAlone) {
  // A flat offset added to what the instrument records, a fraction of each spectrum's peak: named
  // stray_light and nothing else, its size within 10 %. At 8 % of the peak it is about a fifth of
  // the mean signal, which the plausible range once measured against the mean signal set aside.
  for (double m : {0.01, 0.08}) {
    SCOPED_TRACE(m);
    auto data = make("offset_peak", 28, m);
    Outcome r = diagnose_independent(data, 3);
    EXPECT_EQ(r.first(), "stray_light") << r.all();
    EXPECT_EQ(r.d.causes.size(), 1u) << r.all();
    EXPECT_TRUE(r.d.set_aside.empty()) << r.all();
    if (r.first() == "stray_light") EXPECT_NEAR(r.estimate("fraction_of_peak"), m, 0.1 * m) << r.all();
  }
}

TEST(DiagnoseIndependent, AnUnknownBandIsFoundWithinFiveNanometres) {
  // Two shapes the model does not have: a Gaussian in wavenumber (the symmetric limit of its
  // log-normal) and a band skewed in wavelength (half widths 18 and 36 nm). Named alone: before the
  // band was log-normal (a Gaussian in wavelength) stray light followed it in 2 of 4 benchmark runs.
  for (const char* shape : {"wavenumber", "skewed"}) {
    SCOPED_TRACE(shape);
    indep::Options o;
    o.effect = "unknown_fluorophore";
    o.seed = 25;
    o.magnitude = 600;
    o.band_shape = shape;
    auto data = indep::make_independent(o);
    Outcome r = diagnose_independent(data);
    const CauseResult* band = nullptr;
    for (auto& c : r.d.causes)
      if (r.p->candidates()[c.candidate].id == "unknown_band") band = &c;
    ASSERT_NE(band, nullptr) << r.all();
    EXPECT_EQ(r.d.causes.size(), 1u) << r.all();
    EXPECT_NEAR(cause_estimate(*r.p, *band, "center_nm").value, data.truth.at("peak_nm"), 5.0) << r.all();
    // The free-form estimate (curve resolution of the residuals) peaks there too.
    UnknownBandReport ub = unknown_band_report(*r.p, r.d);
    ASSERT_TRUE(ub.accepted && ub.estimate.found);
    EXPECT_NEAR(ub.estimate.peak_nm, data.truth.at("peak_nm"), 5.0);
    EXPECT_GT(ub.estimate.mean_fraction, 0.03);
  }
}

TEST(DiagnoseIndependent, ACauseOfOneSubjectIsFoundAndAttributedToIt) {
  auto data = make("subset_chlorophyll", 26, 0.3);
  Outcome r = diagnose_independent(data);
  EXPECT_EQ(r.first(), "extra_fluorophore:chlorophyll_a") << r.all();
  ASSERT_FALSE(r.d.causes.empty());
  const auto& carriers = r.d.causes[0].trial.carriers;
  EXPECT_NE(std::find(carriers.begin(), carriers.end(), data.carrier), carriers.end())
      << "expected " << data.carrier << " among the carriers of " << r.all();
}

TEST(DiagnoseIndependent, NullDataGetNoTissueCause) {
  // Null data, also with the instrument slightly other than the model says (a long-pass edge 1.5x
  // less steep, 3 nm more blur): instrument causes may be named, tissue causes not.
  for (auto [seed, error] : std::vector<std::pair<uint64_t, std::string>>{{31, ""}, {32, ""}, {33, "edge_width"}, {34, "blur"}}) {
    indep::Options o;
    o.seed = seed;
    o.instrument_error = error;
    auto data = indep::make_independent(o);
    Outcome r = diagnose_independent(data);
    for (auto& c : r.d.causes)
      EXPECT_TRUE(r.p->candidates()[c.candidate].instrument) << "seed " << seed << " " << error << ": " << r.all();
  }
}

TEST(DiagnoseIndependent, FitOnTwoSubjectsPredictsTheOtherTwoAtTheNoise) {
  // An emission shift of 2 nm in every subject: fitted on S1 and S2 only, the causes with their
  // global parameters fixed must predict S3 and S4 about as well as the noise floor allows (the
  // replicate scatter), and far better than the baseline fitted on the same subjects.
  auto data = make("emission_shift", 27, 2.0);
  SpectraSet fit = data.set, pred = data.set;
  std::erase_if(fit.spectra, [](const MeasuredSpectrum& s) { return s.conditions.at("subject") > "S2"; });
  std::erase_if(pred.spectra, [](const MeasuredSpectrum& s) { return s.conditions.at("subject") <= "S2"; });
  SpectraProblem pf(fit, data.model), pp(pred, data.model);
  SelectionOptions o;
  o.group_columns = {"subject", "site"};
  o.replicate_columns = {"subject", "site", "light_nm"};
  o.max_causes = 2;
  Diagnosis d = diagnose(pf, o);
  ASSERT_FALSE(d.causes.empty()) << d.verdict;
  EXPECT_EQ(pf.candidates()[d.causes[0].candidate].id, "emission_shift") << d.verdict;
  CrossSubjectPrediction c = predict_other_subjects(pf, d, pp);
  const PredictionRow& all = c.rows.back();
  EXPECT_EQ(all.subject, "all");
  EXPECT_EQ(all.spectra, pp.num_items());
  // Measured: baseline 0.021, extended 0.0167, noise floor 0.0118 (1.42x) (a 2 nm shift is a small
  // effect at 405/415 nm; the 450 nm rows go from 0.03 to 0.02).
  EXPECT_LT(all.rmse_mean_extended, 1.6 * d.floor.rmse) << "floor " << d.floor.rmse << prediction_text(c);
  EXPECT_LT(all.rmse_mean_extended, 0.85 * all.rmse_mean_baseline) << d.verdict << prediction_text(c);
}
