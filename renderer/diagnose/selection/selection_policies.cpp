#include "renderer/diagnose/selection/selection_policies.h"

#include <cmath>
#include <string>

namespace ofl {

namespace {

// The best-fitting trial among those whose held-out statistics pass (largest gain beyond its
// optimism), when it is not accepted because an estimate is implausible or rests on a bound.
// Trials turned down only in favour of an alternative (one width for all, a per-fluorophore shape)
// are not "set aside": their rival is as good.
const CandidateTrial* best_set_aside(const std::vector<CandidateTrial>& trials) {
  const CandidateTrial* best = nullptr;
  for (auto& t : trials)
    if (t.statistics_ok && (!best || t.mean_gain - t.optimism > best->mean_gain - best->optimism)) best = &t;
  if (!best || best->accepted || (best->implausible.empty() && best->at_bound.empty())) return nullptr;
  return best;
}

}  // namespace

std::pair<double, double> gain_difference(const CandidateTrial& a, const CandidateTrial& b) {
  const size_t M = a.cv.item_mse.size();
  if (M < 2 || b.cv.item_mse.size() != M) return {0, 0};
  std::vector<double> d(M);
  double m = 0;
  for (size_t i = 0; i < M; ++i) { d[i] = b.cv.item_mse[i] - a.cv.item_mse[i]; m += d[i]; }
  m /= M;
  double v = 0;
  for (double x : d) v += (x - m) * (x - m);
  return {m, std::sqrt(v / (M - 1) / M)};
}

void prefer_single_width(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials, double z) {
  CandidateTrial* global = nullptr;
  CandidateTrial* each = nullptr;
  for (auto& t : trials) {
    if (p.candidates()[t.candidate].name == "emission_broadening") global = &t;
    if (p.candidates()[t.candidate].name == "emission_width_each") each = &t;
  }
  if (!global || !each || !global->accepted || !each->accepted) return;
  auto [m, se] = gain_difference(*each, *global);
  if (!(m > z * se)) {
    each->accepted = false;
    each->verdict = "no better held out than one width for all fluorophores (difference " + verdict_number(m) + " +/- " + verdict_number(se) + ")";
  }
}

void reject_dominated_global_broadening(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials) {
  for (auto& t : trials) {
    if (p.candidates()[t.candidate].name != "emission_broadening" || !t.accepted) continue;
    for (auto& u : trials) {
      const std::string& n = p.candidates()[u.candidate].name;
      bool per_fluorophore = n == "emission_width" || n == "emission_width_each" || n == "emission_shift" || n == "second_band";
      if (per_fluorophore && p.candidates()[u.candidate].id != "emission_shift" && &u != &t &&
          u.mean_gain - u.optimism >= t.mean_gain - t.optimism && u.accepted) {
        t.accepted = false;
        t.verdict = "a per-fluorophore alternative (" + p.candidates()[u.candidate].id + ") explains as much held out";
        break;
      }
    }
  }
}

void accept_unlike_any_instrument(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials, double z) {
  std::vector<const CandidateTrial*> instrument;
  for (auto& u : trials)
    if (p.candidates()[u.candidate].instrument) instrument.push_back(&u);
  if (instrument.empty()) return;
  for (auto& t : trials) {
    if (!t.below_floor_only || t.accepted) continue;
    bool ok = true;
    std::string closest;
    double closest_margin = 1e300;
    for (const CandidateTrial* u : instrument) {
      auto [m, se] = gain_difference(t, *u);
      m -= t.optimism - u->optimism;
      if (!(se > 0 && m > z * se)) {
        ok = false;
        break;
      }
      if (m / se < closest_margin) {
        closest_margin = m / se;
        closest = p.candidates()[u->candidate].id;
      }
    }
    if (!ok) continue;
    t.accepted = true;
    t.verdict = "below the noise floor on data that nearly fit, but significantly better held out than every instrument cause "
                "(closest: " + closest + ", " + verdict_number(closest_margin) + " standard errors)";
  }
}

const CandidateTrial* hold_to_set_aside(const DiagnoseProblem& p, std::vector<CandidateTrial>& trials, double z) {
  const CandidateTrial* aside = best_set_aside(trials);
  if (!aside) return nullptr;
  for (auto& t : trials) {
    if (!t.accepted) continue;
    auto [m, se] = gain_difference(*aside, t);
    m -= aside->optimism - t.optimism;
    if (m > z * se) {
      t.accepted = false;
      t.verdict = "significantly worse held out than " + p.candidates()[aside->candidate].id + ", which was set aside (" +
                  verdict_number(m) + " +/- " + verdict_number(se) + " in held-out MSE)";
    }
  }
  return aside;
}

int best_accepted(const std::vector<CandidateTrial>& trials) {
  int best = -1;
  for (size_t k = 0; k < trials.size(); ++k)
    if (trials[k].accepted &&
        (best < 0 || trials[k].mean_gain - trials[k].optimism > trials[best].mean_gain - trials[best].optimism))
      best = static_cast<int>(k);
  return best;
}

}  // namespace ofl
