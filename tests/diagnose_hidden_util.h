// Shared by the hidden-effect tests: run a diagnosis on synthetic data and check the outcome.
#pragma once
#include <cmath>
#include <memory>
#include <string>

#include "renderer/diagnose/selection/cross_validation.h"
#include "tests/support/synthetic.h"

namespace ofl {

struct HiddenOutcome {
  std::string named;          // first cause named ("" = none)
  int causes = 0;
  std::string detail;         // for failure messages
  bool params_ok = true;
};

inline HiddenOutcome judge_outcome(const DiagnoseProblem& p, const Diagnosis& d, const SyntheticData& truth,
                                   const std::string& effect_name) {
  HiddenOutcome o;
  o.causes = static_cast<int>(d.causes.size());
  o.named = d.causes.empty() ? "" : p.candidates()[d.causes[0].candidate].id;
  o.detail = "hidden \"" + truth.effect_id + "\", named \"" + o.named + "\" (" + d.verdict + ")";
  if (!d.causes.empty() && o.named == truth.effect_id)
    for (auto& [name, v] : truth.truth) {
      double est = cause_estimate(p, d.causes[0], name).value;
      double tol = stated_tolerance(effect_name, v);
      o.detail += "; " + name + " true " + std::to_string(v) + " estimated " + std::to_string(est) + " (tolerance " + std::to_string(tol) + ")";
      if (!(std::fabs(est - v) <= tol)) o.params_ok = false;
    }
  return o;
}

}  // namespace ofl
