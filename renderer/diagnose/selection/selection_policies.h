// The selection rules that compare the trials of one step of forward selection with each other.
// `judge` (cross_validation.cpp) decides each candidate on its own: held-out gain against the noise
// floor, folds improved, effect size, plausibility, bounds. These rules then turn some of those
// decisions where two trials of the same step compete for one explanation; each changes only the
// `accepted` flag and the `verdict` of the trials it turns. `selection_step` (cross_validation.cpp)
// applies them in the order they are declared here, then adds the trial best_accepted names.
#pragma once
#include <utility>
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"
#include "renderer/diagnose/selection/trial.h"

namespace ofl {

// Per-item held-out gain of trial a over trial b (same step, same "before"): the mean over items
// of b's held-out MSE minus a's, and its standard error. What every rule below compares.
std::pair<double, double> gain_difference(const CandidateTrial& a, const CandidateTrial& b);

// Decides: a tissue cause turned down only by the instrument-mismatch size bar (`below_floor_only`)
// is accepted after all when it predicts the held-out items significantly better (z standard
// errors of the per-item difference, optimism charged) than every instrument cause tried at the
// same step. Why: on data that nearly fit, a tissue cause must explain the noise floor, since a
// slightly wrong instrument description leaves residuals of that size; a smaller tissue cause is
// still named when the residual is specifically its shape. Needs at least one instrument cause
// to compare. The selection applies it only while no cause has been accepted yet.
void accept_unlike_any_instrument(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials, double z);

// Decides: between one emission width per fluorophore (emission_width_each) and one width for all
// (emission_broadening), both accepted, the per-fluorophore widths are turned down unless they
// predict held-out data significantly better (z standard errors of the per-item difference).
// Why: one width per fluorophore contains the single global width; the simpler explanation wins
// a tie.
void prefer_single_width(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials, double z);

// Decides: a global broadening of every fluorophore (emission_broadening) is turned down when an
// accepted per-fluorophore shape cause (a width, shift or second band of one named fluorophore)
// explains as much held out (gain beyond optimism). Why (docs/diagnose.md, the selection): the
// global broadening stays one candidate among the per-fluorophore ones, not the default reading
// of broad bands; when one named fluorophore's shape explains as much, that is what is reported.
void reject_dominated_global_broadening(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials);

// Decides: when the best-fitting trial (largest gain beyond optimism among those whose held-out
// statistics pass) is not accepted because an estimate is implausible or rests on a bound, every
// accepted trial that predicts the held-out items significantly worse than it (z standard errors
// of the per-item difference of held-out MSE, the extra amplitudes' optimism charged) is turned
// down. Why: plausibility never silently swaps in a worse explanation. Returns the set-aside trial
// (nullptr when there is none); trials turned down only in favour of an alternative (the rules
// above) are not set aside, their rival is as good.
const CandidateTrial* hold_to_set_aside(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials, double z);

// Decides which accepted trial enters the model at this step: the one with the largest
// optimism-corrected held-out gain; -1 when none is accepted (the selection ends).
int best_accepted(const std::vector<CandidateTrial>& trials);

}  // namespace ofl
