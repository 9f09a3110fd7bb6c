// Fitting the global parameters of a model state (baseline and active causes) to a set of items:
// bounded Levenberg-Marquardt on the stacked residuals, with the per-item local amplitudes solved
// inside every evaluation (variable projection) and a forward-difference Jacobian. Causes whose
// effect starts at second order (a blur of width 0, a shift of 0) are started from a small grid.
#pragma once
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"

namespace ofl {

struct GlobalFitOptions {
  int max_iterations = 40;
  double rel_tolerance = 1e-7;  // stop when the sum of squares improves by less than this fraction
  bool uncertainties = true;    // J^T J and standard errors at the optimum (one more Jacobian)
};
// What the cross-validation of a candidate needs: a prediction, not uncertainties, from a warm
// start (the previous step's fold fits), so fewer iterations and a looser tolerance.
inline GlobalFitOptions trial_fit_options() {
  GlobalFitOptions o;
  o.max_iterations = 15;
  o.rel_tolerance = 1e-6;
  o.uncertainties = false;
  return o;
}

struct GlobalFit {
  ModelState state;
  double rss = 0;
  long n_obs = 0;
  int local_dofs = 0;          // sum over items of local amplitudes used
  Eigen::MatrixXd jtj;         // J^T J at the optimum (global parameters, flattened)
  std::vector<double> se;      // curvature standard errors, s^2 (J^T J)^-1, flattened order
  int iterations = 0;
};

// Flattened parameter specs of a state: baseline first, then each cause in order.
std::vector<ParamSpec> state_param_specs(const DiagnoseProblem& p, const ModelState& s);
std::vector<double> flatten(const ModelState& s);
void unflatten(ModelState& s, const std::vector<double>& x);

// Fits every global parameter of `start` on `items`. When `grid_cause` >= 0, that cause's
// parameters are first set to the best point of their start grid (others held at `start`).
GlobalFit fit_global(const DiagnoseProblem& p, ModelState start, const std::vector<int>& items, int grid_cause = -1,
                     const GlobalFitOptions& opt = {});

// A state with the baseline parameters at their initial values and no causes.
ModelState baseline_state(const DiagnoseProblem& p);
// `s` plus candidate `c` at its initial parameters.
ModelState with_cause(const DiagnoseProblem& p, ModelState s, int c);

}  // namespace ofl
