// Honest selection of causes: leave-one-group-out cross-validation (groups = distinct values of
// condition columns such as subject and session) judged against a noise floor measured from
// replicates (items equal in every replicate column, e.g. two locations of the same condition).
// The floor is the "pure error" of the baseline fit: the scatter of the residuals within each
// replicate set. What replicates share is lack of fit (something a cause may explain); what
// differs between them (noise, location-to-location differences the per-item amplitudes cannot
// absorb) is what no global model can predict.
//
// A candidate cause is added to the model (forward selection, best first) only when, on the
// held-out groups,
//   mean_i (MSE_before_i - MSE_after_i) > optimism + z * max(sd_noise, se_items)
// where optimism = dp * s^2 / n_eff is the improvement that dp extra per-item amplitudes give on
// pure noise of variance s^2 (the noise floor) with n_eff effectively independent samples per
// item, sd_noise = s^2 sqrt(2 max(dp,1)) / n_eff / sqrt(M) its spread over M held-out items, and
// se_items the observed standard error of the per-item gains; when more than
// `min_fold_fraction` of the folds improve; and when the effect it explains is not negligible
// against the noise (sqrt(gain - optimism) >= min_effect_to_noise * noise floor RMSE).
// Otherwise: "no significant effect".
#pragma once
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"
#include "renderer/diagnose/selection/global_fit.h"
#include "renderer/diagnose/selection/trial.h"

namespace ofl {

struct SelectionOptions {
  std::vector<std::string> group_columns = {"subject"};  // one fold per distinct combination
  std::vector<std::string> replicate_columns;             // equal in all of these = replicates
  std::string report_by;                                  // per-value breakdown in the report
  double z = 3.0;
  int max_causes = 4;
  double min_fold_fraction = 0.5;
  // Practical significance: the effect the cause explains on held-out data, as an RMS size
  // sqrt(gain - optimism), must be at least this fraction of the noise floor's RMSE. With many
  // spectra a 0.04 nm edge shift (grid discretisation) is statistically clear but not worth naming.
  double min_effect_to_noise = 0.25;
  // A cause carried by a subset of the items (one subject, session, site or light) is accepted
  // when, on that subset's held-out items, it passes the same test with z raised for the number
  // of subsets tried (z + sqrt(2 ln K)), and it does not significantly worsen the other items.
  // Columns whose values define the subsets (those absent from the data are skipped).
  std::vector<std::string> subset_columns = {"subject", "date", "site", "light_nm"};
  // Instrument mismatch: once the model in hand nearly fits (full-fit RMSE below
  // `mismatch_max_lack_of_fit` x the noise floor), what is left is as likely a slightly wrong
  // instrument or library description as tissue, so tissue causes must explain at least
  // `mismatch_tissue_min_effect` x the noise floor to be named. When the baseline nearly fits and
  // most of its residual is one shape shared by every item (share above
  // `mismatch_min_common_share`) the verdict says "instrument mismatch".
  double mismatch_max_lack_of_fit = 2.0;
  double mismatch_min_common_share = 0.5;
  double mismatch_tissue_min_effect = 1.0;
  // One instrument: the accepted instrument causes are fitted jointly on every item; as a check
  // only, the final model is refitted on each value of this column alone (e.g. each subject) and
  // the instrument parameters found there are reported next to the joint ones ("" or a column the
  // data lack: no check).
  std::string check_by = "subject";
  bool parallel = true;
  // For library callers (the Python module): called after each candidate cause is tried, from any
  // worker thread, with (cause step, candidates done, candidates in this step). Returning false
  // stops the diagnosis: the candidates in flight finish, then Interrupted is thrown.
  std::function<bool(int step, int64_t done, int64_t total)> progress;
};

struct NoiseFloor {
  double variance = 0;     // per residual element (problem units squared)
  double rmse = 0;
  double n_eff_ratio = 1;  // independent samples per residual element (lag-1 autocorrelation)
  double lag1 = 0;
  int sets = 0, items = 0;
  std::string source;      // how it was measured, in words
  bool instrument_mismatch = false;  // set by diagnose() (SelectionOptions: instrument mismatch)
};
// Pure error of `fits` (one per item, e.g. the baseline fitted to all items) within replicate sets.
NoiseFloor estimate_noise_floor(const DiagnoseProblem& p, const std::vector<std::string>& replicate_columns,
                                const std::vector<ItemFit>& fits);

struct Folds {
  std::vector<std::string> names;
  std::vector<int> of_item;
  int count() const { return static_cast<int>(names.size()); }
};
Folds make_folds(const DiagnoseProblem& p, const std::vector<std::string>& columns);

// Fits `fold_starts[f]` on all folds but f and predicts fold f; `grid_cause` as in fit_global.
CvRun cross_validate(const DiagnoseProblem& p, const std::vector<ModelState>& fold_starts, int grid_cause,
                     const Folds& folds, bool parallel, const GlobalFitOptions& fit = trial_fit_options());

struct GroupGain {
  std::string value;
  int items = 0;
  double rmse_before = 0, rmse_after = 0;
  double ve_before = 0, ve_after = 0;  // variance explained
};

struct CauseResult {
  int candidate = -1;
  int step = 0;
  std::vector<double> theta, uncertainty, se_curvature, se_jackknife;
  std::vector<DerivedParam> derived;
  CandidateTrial trial;                 // the step at which it was accepted
  CandidateTrial solo;                  // on top of the baseline alone (step 1)
  std::vector<GroupGain> by_report;     // incremental held-out gain per report_by value
  std::vector<GroupGain> solo_by_report;
  std::vector<std::string> at_bound;    // parameters of the full fit that end on a bound
  std::string words;
};

// A candidate that predicted the held-out data best at a step but was set aside as implausible or
// resting on a bound. Plausibility never silently swaps in a worse explanation: the verdict names
// it first, and another candidate is accepted at that step only if it is not significantly worse
// held out.
struct SetAside {
  int step = 0;
  int candidate = -1;
  double rmse_before = 0, rmse_after = 0;
  std::string reason;   // the implausible estimate or the bound
  std::string words;    // the cause in plain words with its estimates (mean of the fold fits)
  std::string instead;  // id of the candidate accepted at that step instead ("" = none)
};

// One instrument parameter fitted jointly and, as a check, on each value of a column alone.
struct InstrumentCheck {
  std::string cause_id, param;
  double joint = 0, uncertainty = 0;
  std::vector<std::pair<std::string, double>> by_value;  // (value of check_by, fitted on its items alone)
  // The per-value fits differ by more than 3 standard errors of a fit on one value (the joint
  // uncertainty x sqrt(number of values), x sqrt 2 for a difference): the joint cause averages
  // something that differs between them, which one instrument should not.
  bool disagree = false;
};

struct Diagnosis {
  SelectionOptions options;
  NoiseFloor floor;
  Folds folds;
  CvRun baseline_cv, final_cv;
  GlobalFit baseline_fit, final_fit;
  std::vector<CauseResult> causes;
  std::vector<std::vector<CandidateTrial>> steps;  // every candidate tried at every step
  std::vector<SetAside> set_aside;                 // best-fitting candidates set aside, per step
  std::vector<InstrumentCheck> instrument_check;   // accepted instrument causes per value of check_by
  double rmse_baseline_heldout = 0, rmse_extended_heldout = 0;
  double ve_baseline_heldout = 0, ve_extended_heldout = 0;
  std::vector<GroupGain> by_report, by_fold;
  // Lack of fit of the baseline and how much of it one residual shape shared by every item
  // explains (an instrument mismatch rather than tissue when that share is large).
  double baseline_lack_of_fit = 0;     // baseline full-fit RMSE / noise floor RMSE
  double common_shape_share = 0;       // fraction of the residual sum of squares
  std::vector<double> common_shape_nm, common_shape;  // the mean residual (first item's abscissa)
  bool instrument_mismatch = false;
  std::string verdict;
};

Diagnosis diagnose(const DiagnoseProblem& p, const SelectionOptions& o);

// What a cause reports for one of its parameters or derived quantities, found by name.
struct CauseEstimate {
  double value = NAN, uncertainty = NAN;
};
// NaN value and uncertainty when the cause has no parameter or derived quantity of that name.
CauseEstimate cause_estimate(const DiagnoseProblem& p, const CauseResult& c, const std::string& name);

// Held-out RMSE and variance explained of a CV run, before/after, over `items`.
GroupGain group_gain(const DiagnoseProblem& p, const CvRun& before, const CvRun& after, const std::vector<int>& items,
                     const std::string& name);

}  // namespace ofl
