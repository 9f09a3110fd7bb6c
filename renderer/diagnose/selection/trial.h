// One candidate cause tried at one step of forward selection: its cross-validation run and what
// was decided about it. `judge` (cross_validation.cpp) decides each trial on its own; the rules of
// selection_policies.h then compare the trials of one step with each other.
#pragma once
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"

namespace ofl {

struct CvRun {
  std::vector<ItemFit> heldout;          // per item
  std::vector<double> item_mse;          // per item
  std::vector<ModelState> fold_states;   // global parameters fitted without that fold
  double rss = 0;
  long n = 0;
  double rmse() const { return n ? std::sqrt(rss / n) : 0; }
};

struct CandidateTrial {
  int candidate = -1;
  double rmse_before = 0, rmse_after = 0;  // pooled over held-out items
  double mean_gain = 0;                    // mean over items of MSE_before - MSE_after
  double optimism = 0, sd_noise = 0, se_items = 0, threshold = 0;
  int folds_improved = 0, folds = 0;
  bool accepted = false;
  std::string carried_by;                  // "column=value" when only a subset carries the gain
  std::vector<std::string> carriers;       // subsets that carry it when they are a minority of their column
  double subset_gain = 0, subset_threshold = 0;
  std::vector<std::string> at_bound;       // parameters that end on a bound in most fold fits
  std::vector<std::string> implausible;    // estimates outside the cause's plausible range
  // A tissue cause that passes every test but the instrument-mismatch size bar (its effect is
  // below the noise floor on data that nearly fit): it is still named if it predicts the held-out
  // data significantly better than every instrument cause tried at the same step.
  bool below_floor_only = false;
  // Its held-out statistics pass (pooled or on a carrying subset), whatever else is said of it.
  bool statistics_ok = false;
  std::string verdict;
  CvRun cv;
};

// A number in a verdict: four significant digits.
inline std::string verdict_number(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

}  // namespace ofl
