#include "renderer/diagnose/selection/cross_validation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "renderer/core/errors/error.h"
#include "renderer/core/process/progress.h"
#include "renderer/diagnose/selection/selection_policies.h"

namespace ofl {

namespace {

std::string key_of(const DiagnoseProblem& p, int i, const std::vector<std::string>& cols) {
  std::string k;
  for (auto& c : cols) k += (k.empty() ? "" : ", ") + c + "=" + p.condition(i, c);
  return k;
}

std::vector<int> all_items(const DiagnoseProblem& p) {
  std::vector<int> v(p.num_items());
  for (int i = 0; i < p.num_items(); ++i) v[i] = i;
  return v;
}

}  // namespace

NoiseFloor estimate_noise_floor(const DiagnoseProblem& p, const std::vector<std::string>& cols, const std::vector<ItemFit>& fits) {
  NoiseFloor nf;
  std::map<std::string, std::vector<int>> sets;
  if (!cols.empty())
    for (int i = 0; i < p.num_items(); ++i) sets[key_of(p, i, cols)].push_back(i);
  double ss = 0, dof = 0, lag_num = 0, lag_den = 0;
  for (auto& [k, items] : sets) {
    if (items.size() < 2) continue;
    const Eigen::Index n = fits[items[0]].residual.size();
    bool same = true;
    for (int i : items) same = same && fits[i].residual.size() == n;
    if (!same) continue;
    Eigen::VectorXd m = Eigen::VectorXd::Zero(n);
    double local = 0;
    for (int i : items) {
      m += fits[i].residual;
      local += fits[i].local_dofs;
    }
    m /= static_cast<double>(items.size());
    local /= static_cast<double>(items.size());
    for (int i : items) {
      Eigen::VectorXd r = fits[i].residual - m;
      ss += r.squaredNorm();
      if (r.size() >= 8) {
        lag_num += r.head(r.size() - 1).dot(r.tail(r.size() - 1));
        lag_den += r.squaredNorm();
      }
    }
    // Each residual already lost `local` degrees of freedom to its own amplitudes.
    dof += (items.size() - 1.0) * std::max(1.0, static_cast<double>(n) - local);
    ++nf.sets;
    nf.items += static_cast<int>(items.size());
  }
  if (nf.sets > 0 && dof > 0) {
    nf.variance = ss / dof;
    nf.lag1 = lag_den > 0 ? std::clamp(lag_num / lag_den, 0.0, 0.98) : 0.0;
    nf.n_eff_ratio = (1 - nf.lag1) / (1 + nf.lag1);
    nf.source = "pure error of the baseline fit within replicate sets (" + std::to_string(nf.sets) + " sets, " +
                std::to_string(nf.items) + " items)";
  } else {
    double v = p.fallback_noise_variance();
    if (v > 0) {
      nf.variance = v;
      nf.source = p.kind() == "spectra" ? "high-frequency scatter of the spectra (no replicates; a lower bound)"
                                        : "patch standard deviations / sqrt(pixels) (no replicates)";
    } else {
      nf.source = "none (no replicates and no other noise estimate)";
    }
  }
  nf.rmse = std::sqrt(nf.variance);
  return nf;
}

Folds make_folds(const DiagnoseProblem& p, const std::vector<std::string>& cols) {
  Folds f;
  std::map<std::string, int> idx;
  for (int i = 0; i < p.num_items(); ++i) {
    std::string k = key_of(p, i, cols);
    auto it = idx.find(k);
    if (it == idx.end()) {
      it = idx.emplace(k, static_cast<int>(f.names.size())).first;
      f.names.push_back(k);
    }
    f.of_item.push_back(it->second);
  }
  return f;
}

CvRun cross_validate(const DiagnoseProblem& p, const std::vector<ModelState>& starts, int grid_cause, const Folds& folds,
                     bool parallel, const GlobalFitOptions& fo) {
  const int G = folds.count();
  CvRun run;
  run.heldout.resize(p.num_items());
  run.item_mse.assign(p.num_items(), 0.0);
  run.fold_states.resize(G);
  auto one = [&](int g) {
    std::vector<int> train, test;
    for (int i = 0; i < p.num_items(); ++i) (folds.of_item[i] == g ? test : train).push_back(i);
    GlobalFit fit = fit_global(p, starts[g], train, grid_cause, fo);
    p.fill_unfitted(fit.state, train);
    run.fold_states[g] = fit.state;
    auto fits = p.evaluate(fit.state, test);
    for (size_t k = 0; k < test.size(); ++k) {
      run.item_mse[test[k]] = fits[k].residual.squaredNorm() / std::max<Eigen::Index>(1, fits[k].residual.size());
      run.heldout[test[k]] = std::move(fits[k]);
    }
  };
  if (parallel)
    tbb::parallel_for(0, G, one);
  else
    for (int g = 0; g < G; ++g) one(g);
  for (auto& f : run.heldout) {
    run.rss += f.residual.squaredNorm();
    run.n += f.residual.size();
  }
  return run;
}

GroupGain group_gain(const DiagnoseProblem& p, const CvRun& a, const CvRun& b, const std::vector<int>& items,
                     const std::string& name) {
  const size_t M = static_cast<size_t>(p.num_items());
  if (a.heldout.size() != M || b.heldout.size() != M)
    throw std::logic_error("group_gain: a cross-validation run without a held-out fit for every item (" + name + ")");
  GroupGain g;
  g.value = name;
  g.items = static_cast<int>(items.size());
  double ra = 0, rb = 0, tot = 0;
  long n = 0;
  for (int i : items) {
    ra += a.heldout[i].residual.squaredNorm();
    rb += b.heldout[i].residual.squaredNorm();
    n += a.heldout[i].residual.size();
    tot += p.centred_sum_of_squares(i);
  }
  g.rmse_before = n ? std::sqrt(ra / n) : 0;
  g.rmse_after = n ? std::sqrt(rb / n) : 0;
  g.ve_before = tot > 0 ? 1 - ra / tot : 0;
  g.ve_after = tot > 0 ? 1 - rb / tot : 0;
  return g;
}

namespace {

// The smallest effect (x the noise floor) for which a cause is named. `mismatch`: the baseline
// shows an instrument mismatch (SelectionOptions), which raises the bar for tissue causes.
double min_effect_of(const CandidateSpec& c, const SelectionOptions& o, bool mismatch) {
  double m = std::isnan(c.min_effect_to_noise) ? o.min_effect_to_noise : c.min_effect_to_noise;
  if (mismatch && !c.instrument) m = std::max(m, o.mismatch_tissue_min_effect);
  return m;
}

// Held-out gain statistics of a candidate over a set of items.
struct GainStats {
  double mean = 0, optimism = 0, se = 0, sd_noise = 0;
  int n = 0;
  double threshold(double z) const { return optimism + z * std::max(sd_noise, se); }
};

GainStats gain_stats(const std::vector<double>& d, const std::vector<double>& mu, const std::vector<double>& sd2,
                     const std::vector<int>& items) {
  GainStats g;
  g.n = static_cast<int>(items.size());
  if (items.empty()) return g;
  double s2 = 0;
  for (int i : items) { g.mean += d[i]; g.optimism += mu[i]; s2 += sd2[i]; }
  g.mean /= g.n;
  g.optimism /= g.n;
  double var = 0;
  for (int i : items) var += (d[i] - g.mean) * (d[i] - g.mean);
  g.se = g.n > 1 ? std::sqrt(var / (g.n - 1) / g.n) : 0;
  g.sd_noise = std::sqrt(s2 / g.n) / std::sqrt(static_cast<double>(g.n));
  return g;
}

// Parameters of the candidate (the last cause of every fold's state) that end on one of their
// bounds in more than half of the fold fits.
std::vector<std::string> params_at_bound(const DiagnoseProblem& p, int cand, const CvRun& after) {
  std::vector<std::string> out;
  const auto& spec = p.candidates()[cand];
  for (size_t k = 0; k < spec.params.size(); ++k) {
    const ParamSpec& ps = spec.params[k];
    if (ps.lo == ps.hi) continue;  // fixed by the model (a one-value grid): not pushed anywhere
    int at = 0, n = 0;
    for (auto& st : after.fold_states) {
      if (st.causes.empty() || st.causes.back().candidate != cand) continue;
      double v = st.causes.back().theta[k];
      double tol = 1e-3 * std::max(1e-9, std::isfinite(ps.hi - ps.lo) ? ps.hi - ps.lo : std::fabs(v) + 1);
      ++n;
      if ((std::isfinite(ps.lo) && v <= ps.lo + tol) || (std::isfinite(ps.hi) && v >= ps.hi - tol)) ++at;
    }
    // A parameter that rests at its starting value 0 on the lower bound (a cause that is off) is
    // not "pushed to a bound"; only a bound away from the cause's null value counts.
    bool null_bound = ps.lo == ps.init && ps.init == 0;
    if (n && 2 * at > n) {
      double mean = 0;
      for (auto& st : after.fold_states)
        if (!st.causes.empty() && st.causes.back().candidate == cand) mean += st.causes.back().theta[k] / n;
      bool on_lo = std::isfinite(ps.lo) && std::fabs(mean - ps.lo) < std::fabs(mean - ps.hi);
      if (!(on_lo && null_bound)) out.push_back(ps.name + " = " + verdict_number(on_lo ? ps.lo : ps.hi) + " (" + (on_lo ? "lower" : "upper") + " bound)");
    }
  }
  return out;
}

// Estimates outside the candidate's plausible range: global parameters averaged over the fold
// fits, derived quantities from the held-out fits.
std::vector<std::string> implausible_estimates(const DiagnoseProblem& p, int cand, const CvRun& after) {
  std::vector<std::string> out;
  const auto& spec = p.candidates()[cand];
  if (spec.plausible.empty()) return out;
  std::vector<int> all(p.num_items());
  for (int i = 0; i < p.num_items(); ++i) all[i] = i;
  auto derived = p.derived_params(spec, after.heldout, all);
  for (auto& q : spec.plausible) {
    double v = NAN;
    for (size_t k = 0; k < spec.params.size(); ++k)
      if (spec.params[k].name == q.quantity) {
        double m = 0;
        int n = 0;
        for (auto& st : after.fold_states)
          if (!st.causes.empty() && st.causes.back().candidate == cand) { m += st.causes.back().theta[k]; ++n; }
        if (n) v = m / n;
      }
    for (auto& dp : derived)
      if (dp.name == q.quantity) v = dp.value;
    if (std::isfinite(v) && (v < q.lo || v > q.hi))
      out.push_back(q.quantity + " " + verdict_number(v) + " outside [" + verdict_number(q.lo) + ", " + verdict_number(q.hi) + "]: " + q.why);
  }
  return out;
}

// The subsets (column=value) a cause may be carried by: columns with at least two values.
std::vector<std::pair<std::string, std::vector<int>>> item_subsets(const DiagnoseProblem& p, const SelectionOptions& o) {
  std::vector<std::pair<std::string, std::vector<int>>> out;
  for (auto& col : o.subset_columns) {
    std::map<std::string, std::vector<int>> by;
    for (int i = 0; i < p.num_items(); ++i) {
      std::string v = p.condition(i, col);
      if (!v.empty()) by[v].push_back(i);
    }
    if (by.size() < 2) continue;
    for (auto& [v, items] : by)
      if (items.size() >= 2) out.push_back({col + "=" + v, items});
  }
  return out;
}

// Subsets whose held-out gain passes the test on their own, at a z raised for the number of
// subsets tried, without making the other items significantly worse, with an effect that is not
// negligible. Fills the trial's carriers (values of a column that carry the gain when they are a
// minority of that column's values) and returns the best subset's name.
std::string carrying_subsets(const DiagnoseProblem& p, const std::vector<double>& d, const std::vector<double>& mu,
                             const std::vector<double>& sd2, const NoiseFloor& nf, const SelectionOptions& o, CandidateTrial& t) {
  auto subsets = item_subsets(p, o);
  if (subsets.empty()) return "";
  const double z_sub = o.z + std::sqrt(2.0 * std::log(static_cast<double>(subsets.size())));
  const double min_effect = min_effect_of(p.candidates()[t.candidate], o, nf.instrument_mismatch);
  std::string best;
  double best_margin = 0;
  std::map<std::string, std::pair<int, int>> per_column;  // passing, total values
  std::vector<std::string> passing;
  for (auto& [name, items] : subsets) {
    std::string column = name.substr(0, name.find('='));
    per_column[column].second++;
    if (static_cast<int>(items.size()) == p.num_items()) continue;
    GainStats in = gain_stats(d, mu, sd2, items);
    std::vector<int> rest;
    std::vector<char> mark(p.num_items(), 0);
    for (int i : items) mark[i] = 1;
    for (int i = 0; i < p.num_items(); ++i)
      if (!mark[i]) rest.push_back(i);
    GainStats out = gain_stats(d, mu, sd2, rest);
    double thr = in.threshold(z_sub);
    bool effect_ok = std::sqrt(std::max(0.0, in.mean - in.optimism)) >= min_effect * nf.rmse;
    // "Not made worse": the raw held-out change (an unused amplitude changes nothing, so the
    // optimism of the extra amplitudes is not charged here).
    bool rest_ok = out.n == 0 || out.mean > -o.z * std::max(out.se, out.sd_noise);
    if (!(in.mean > thr && effect_ok && rest_ok)) continue;
    per_column[column].first++;
    passing.push_back(name);
    if (in.mean - thr > best_margin) {
      best_margin = in.mean - thr;
      best = name;
      t.subset_gain = in.mean;
      t.subset_threshold = thr;
    }
  }
  for (auto& name : passing) {
    auto& [pass, total] = per_column[name.substr(0, name.find('='))];
    if (2 * pass < total) t.carriers.push_back(name);
  }
  return best;
}

CandidateTrial judge(const DiagnoseProblem& p, int cand, const CvRun& before, CvRun after, const Folds& folds,
                     const NoiseFloor& nf, const SelectionOptions& o) {
  CandidateTrial t;
  t.candidate = cand;
  const int M = p.num_items();
  const int dp = cand >= 0 ? p.candidates()[cand].local_dofs : 0;
  std::vector<double> d(M), mu(M), sd2(M);
  for (int i = 0; i < M; ++i) {
    double n = static_cast<double>(std::max<Eigen::Index>(1, after.heldout[i].residual.size()));
    double neff = std::max(1.0, n * nf.n_eff_ratio);
    d[i] = before.item_mse[i] - after.item_mse[i];
    mu[i] = dp * nf.variance / neff;
    sd2[i] = 2.0 * std::max(dp, 1) * nf.variance * nf.variance / (neff * neff);
  }
  std::vector<int> all(M);
  for (int i = 0; i < M; ++i) all[i] = i;
  GainStats g = gain_stats(d, mu, sd2, all);
  t.se_items = g.se;
  t.sd_noise = g.sd_noise;
  t.mean_gain = g.mean;
  t.optimism = g.optimism;
  t.threshold = g.threshold(o.z);
  t.folds = folds.count();
  for (int f = 0; f < folds.count(); ++f) {
    double s = 0;
    int n = 0;
    for (int i = 0; i < M; ++i)
      if (folds.of_item[i] == f) { s += d[i] - mu[i]; ++n; }
    if (n && s > 0) ++t.folds_improved;
  }
  t.rmse_before = before.rmse();
  t.rmse_after = after.rmse();
  bool gain_ok = g.mean > t.threshold;
  bool folds_ok = t.folds_improved > o.min_fold_fraction * t.folds;
  double effect = std::sqrt(std::max(0.0, g.mean - g.optimism));
  const double min_effect = min_effect_of(p.candidates()[cand], o, nf.instrument_mismatch);
  bool size_ok = effect >= min_effect * nf.rmse;
  bool pooled = gain_ok && folds_ok && size_ok;
  if (g.mean > g.optimism) {
    std::string best = carrying_subsets(p, d, mu, sd2, nf, o, t);
    if (!pooled) t.carried_by = best;
  }
  t.at_bound = params_at_bound(p, cand, after);
  t.implausible = implausible_estimates(p, cand, after);
  t.below_floor_only = gain_ok && folds_ok && !size_ok && nf.instrument_mismatch && t.carried_by.empty() &&
                       effect >= min_effect_of(p.candidates()[cand], o, false) * nf.rmse && t.at_bound.empty() &&
                       t.implausible.empty();
  bool statistics_ok = pooled || !t.carried_by.empty();
  t.statistics_ok = statistics_ok;
  t.accepted = statistics_ok && t.at_bound.empty() && t.implausible.empty();
  if (t.accepted)
    t.verdict = t.carried_by.empty() ? "held-out gain beats the noise"
                                     : "held-out gain beats the noise on " + t.carried_by + " (gain " + verdict_number(t.subset_gain) +
                                           " > " + verdict_number(t.subset_threshold) + "); not on the pooled data";
  else if (statistics_ok && !t.at_bound.empty())
    t.verdict = "not accepted on the strength of a bound: " + t.at_bound[0];
  else if (statistics_ok)
    t.verdict = "implausible: " + t.implausible[0];
  else if (!gain_ok)
    t.verdict = "held-out gain " + verdict_number(g.mean) + " below the threshold " + verdict_number(t.threshold);
  else if (!folds_ok)
    t.verdict = "improves only " + std::to_string(t.folds_improved) + " of " + std::to_string(t.folds) + " held-out groups";
  else
    t.verdict = "significant but negligible: effect RMS " + verdict_number(effect) + " < " + verdict_number(min_effect) + " x noise floor";
  t.cv = std::move(after);
  return t;
}

std::vector<GroupGain> breakdown(const DiagnoseProblem& p, const CvRun& a, const CvRun& b, const std::string& column,
                                 const Folds* folds) {
  std::map<std::string, std::vector<int>> by;
  std::vector<std::string> order;
  for (int i = 0; i < p.num_items(); ++i) {
    std::string v = folds ? folds->names[folds->of_item[i]] : p.condition(i, column);
    if (!by.count(v)) order.push_back(v);
    by[v].push_back(i);
  }
  std::vector<GroupGain> out;
  for (auto& v : order) out.push_back(group_gain(p, a, b, by[v], v));
  return out;
}

// The trial of candidate c on the baseline alone (step 1), or nullptr when c was not tried there:
// a cause that needs another in the model first (the emission shift of an extra fluorophore) is
// first tried at a later step and has no "alone on the baseline" numbers.
const CandidateTrial* solo_trial(const std::vector<CandidateTrial>& step1, int c) {
  for (auto& s : step1)
    if (s.candidate == c) return &s;
  return nullptr;
}

bool requirement_met(const DiagnoseProblem& p, const ModelState& s, int c) {
  const std::string& req = p.candidates()[c].requires_id;
  if (req.empty()) return true;
  for (auto& a : s.causes)
    if (p.candidates()[a.candidate].id == req) return true;
  return false;
}

// A set-aside trial in words: its parameters as the mean of the fold fits (their spread as the
// uncertainty), its derived quantities from the held-out fits.
SetAside describe_set_aside(const DiagnoseProblem& p, const CandidateTrial& t, int step) {
  SetAside a;
  a.step = step;
  a.candidate = t.candidate;
  a.rmse_before = t.rmse_before;
  a.rmse_after = t.rmse_after;
  a.reason = !t.implausible.empty() ? "implausible: " + t.implausible[0] : "on a bound: " + t.at_bound[0];
  const CandidateSpec& c = p.candidates()[t.candidate];
  std::vector<double> mean(c.params.size(), 0.0), sd(c.params.size(), 0.0);
  std::vector<const std::vector<double>*> th;
  for (auto& st : t.cv.fold_states)
    if (!st.causes.empty() && st.causes.back().candidate == t.candidate) th.push_back(&st.causes.back().theta);
  for (size_t k = 0; k < mean.size() && !th.empty(); ++k) {
    for (auto* v : th) mean[k] += (*v)[k] / th.size();
    for (auto* v : th) sd[k] += ((*v)[k] - mean[k]) * ((*v)[k] - mean[k]) / th.size();
    sd[k] = std::sqrt(sd[k]);
  }
  a.words = p.plain_words(c, mean, sd, p.derived_params(c, t.cv.heldout, all_items(p)));
  return a;
}

// The verdict's opening: every step at which the best-fitting candidate was set aside.
std::string set_aside_verdict(const DiagnoseProblem& p, const std::vector<SetAside>& aside) {
  std::string v;
  for (auto& a : aside) {
    v += a.step == 1 ? "the data are best explained by " : "at step " + std::to_string(a.step) + " the data are best explained further by ";
    v += p.candidates()[a.candidate].id + " (held-out RMSE " + verdict_number(a.rmse_before) + " -> " + verdict_number(a.rmse_after) + "), set aside as " +
         a.reason + (a.instead.empty() ? "; nothing else is accepted in its place" : "; accepted in its place, not significantly worse: " + a.instead) +
         "; ";
  }
  return v;
}

// One instrument, checked: the final state refitted on each value of `column` alone, each accepted
// instrument cause's parameters there next to the joint fit's (SelectionOptions::check_by).
std::vector<InstrumentCheck> instrument_checks(const DiagnoseProblem& p, const Diagnosis& dg, const std::string& column) {
  std::vector<InstrumentCheck> out;
  if (column.empty()) return out;
  bool any_instrument = false;
  for (auto& c : dg.causes) any_instrument = any_instrument || (p.candidates()[c.candidate].instrument && !c.theta.empty());
  if (!any_instrument) return out;
  std::map<std::string, std::vector<int>> by;
  for (int i = 0; i < p.num_items(); ++i)
    if (!p.condition(i, column).empty()) by[p.condition(i, column)].push_back(i);
  if (by.size() < 2) return out;
  std::vector<std::pair<std::string, ModelState>> fits;
  for (auto& [v, items] : by) {
    ModelState s = fit_global(p, dg.final_fit.state, items, -1, trial_fit_options()).state;
    p.fill_unfitted(s, items);
    fits.push_back({v, std::move(s)});
  }
  const double K = static_cast<double>(by.size());
  for (size_t k = 0; k < dg.causes.size(); ++k) {
    const CauseResult& c = dg.causes[k];
    const CandidateSpec& spec = p.candidates()[c.candidate];
    if (!spec.instrument) continue;
    for (size_t j = 0; j < c.theta.size() && j < spec.params.size(); ++j) {
      InstrumentCheck ic;
      ic.cause_id = spec.id;
      ic.param = spec.params[j].name;
      ic.joint = c.theta[j];
      ic.uncertainty = c.uncertainty[j];
      double lo = 1e300, hi = -1e300;
      for (auto& [v, s] : fits) {
        double x = s.causes[k].theta[j];
        ic.by_value.push_back({v, x});
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
      ic.disagree = hi - lo > 3 * std::sqrt(2 * K) * ic.uncertainty;
      out.push_back(std::move(ic));
    }
  }
  return out;
}

std::vector<std::string> final_params_at_bound(const CandidateSpec& c, const std::vector<double>& theta) {
  std::vector<std::string> out;
  for (size_t k = 0; k < c.params.size() && k < theta.size(); ++k) {
    const ParamSpec& ps = c.params[k];
    if (ps.lo == ps.hi) continue;  // fixed by the model
    double span = std::isfinite(ps.hi - ps.lo) ? ps.hi - ps.lo : std::fabs(theta[k]) + 1;
    if (std::isfinite(ps.hi) && theta[k] >= ps.hi - 1e-3 * span) out.push_back(ps.name + " at its upper bound " + verdict_number(ps.hi));
    if (std::isfinite(ps.lo) && theta[k] <= ps.lo + 1e-3 * span && !(ps.lo == 0 && ps.init == 0))
      out.push_back(ps.name + " at its lower bound " + verdict_number(ps.lo));
  }
  return out;
}

struct LackOfFit {
  double ratio = 0;         // full-fit RMSE / noise floor RMSE
  double common_share = 0;  // share of the residual sum of squares held by the mean residual
  std::vector<double> nm, shape;
};

// Lack of fit of a fitted state against the noise floor, and the share of its residual that one
// shape common to all items explains (items on the same abscissa only).
LackOfFit lack_of_fit(const DiagnoseProblem& p, const GlobalFit& fit, const NoiseFloor& floor) {
  LackOfFit l;
  const long n = std::max<long>(1, fit.n_obs);
  l.ratio = floor.rmse > 0 ? std::sqrt(fit.rss / n) / floor.rmse : 0;
  std::vector<int> all(p.num_items());
  for (int i = 0; i < p.num_items(); ++i) all[i] = i;
  auto fits = p.evaluate(fit.state, all);
  if (fits.empty()) return l;
  const Eigen::Index len = fits[0].residual.size();
  for (auto& f : fits)
    if (f.residual.size() != len) return l;
  Eigen::VectorXd m = Eigen::VectorXd::Zero(len);
  double total = 0;
  for (auto& f : fits) { m += f.residual; total += f.residual.squaredNorm(); }
  m /= static_cast<double>(fits.size());
  l.common_share = total > 0 ? m.squaredNorm() * fits.size() / total : 0;
  l.nm = p.abscissa(0);
  l.shape.assign(m.data(), m.data() + m.size());
  return l;
}

bool is_mismatch(const LackOfFit& l, const SelectionOptions& o) {
  return l.ratio < o.mismatch_max_lack_of_fit && l.common_share > o.mismatch_min_common_share;
}
// The model in hand already fits within a small multiple of the noise floor: what is left is as
// likely a slightly wrong instrument or library description as tissue.
bool nearly_fits(const LackOfFit& l, const SelectionOptions& o) { return l.ratio < o.mismatch_max_lack_of_fit; }

// Refuses data that give fewer than two cross-validation groups.
void require_two_folds(const Folds& folds, const SelectionOptions& o) {
  if (folds.count() >= 2) return;
  std::string cols;
  for (auto& c : o.group_columns) cols += (cols.empty() ? "" : ",") + c;
  throw InputError("groups", cols.empty() ? "(none)" : cols,
                   "cross-validation needs at least two groups, the data have one (" +
                       (folds.names.empty() ? std::string("no items") : folds.names[0]) + ")");
}

// The baseline: its full-data fit, the noise floor (from replicates, else the baseline residual),
// its lack of fit, and its cross-validation.
void fit_baseline(const DiagnoseProblem& p, const SelectionOptions& o, const std::vector<int>& all, Diagnosis& dg) {
  ModelState base = baseline_state(p);
  dg.baseline_fit = fit_global(p, base, all);
  dg.floor = estimate_noise_floor(p, o.replicate_columns, p.evaluate(dg.baseline_fit.state, all));
  if (dg.floor.variance <= 0) {
    dg.floor.variance = dg.baseline_fit.rss / std::max<long>(1, dg.baseline_fit.n_obs);
    dg.floor.rmse = std::sqrt(dg.floor.variance);
    dg.floor.source = "baseline residual (no replicates and no other noise estimate; conservative)";
  }
  LackOfFit l = lack_of_fit(p, dg.baseline_fit, dg.floor);
  dg.baseline_lack_of_fit = l.ratio;
  dg.common_shape_share = l.common_share;
  dg.common_shape_nm = l.nm;
  dg.common_shape = l.shape;
  dg.instrument_mismatch = is_mismatch(l, o);
  std::vector<ModelState> starts(dg.folds.count(), base);
  dg.baseline_cv = cross_validate(p, starts, -1, dg.folds, o.parallel, GlobalFitOptions{});
}

// Cross-validates each candidate in `todo` added to the current fold states (in parallel when
// allowed), with a progress bar; stops on SIGINT or when SelectionOptions::progress says so.
std::vector<CvRun> cross_validate_candidates(const DiagnoseProblem& p, const SelectionOptions& o, const Folds& folds,
                                             const CvRun& current, const std::vector<int>& todo, int step) {
  std::vector<CvRun> runs(todo.size());
  ProgressBar bar("diagnose: cause " + std::to_string(step) + ", candidates", static_cast<int64_t>(todo.size()));
  std::atomic<int64_t> tried{0};
  std::atomic<bool> stop{false};  // SelectionOptions::progress said stop
  auto run_one = [&](size_t k) {
    if (stop || interrupt_requested()) return;  // the step ends at the check after the candidates
    std::vector<ModelState> st;
    for (int g = 0; g < folds.count(); ++g) st.push_back(with_cause(p, current.fold_states[g], todo[k]));
    runs[k] = cross_validate(p, st, static_cast<int>(st[0].causes.size()) - 1, folds, false);
    bar.advance();
    if (o.progress && !o.progress(step, ++tried, static_cast<int64_t>(todo.size()))) stop = true;
  };
  if (o.parallel)
    tbb::parallel_for(size_t(0), todo.size(), run_one);
  else
    for (size_t k = 0; k < todo.size(); ++k) run_one(k);
  if (stop) throw Interrupted("diagnose stopped by its progress callback");
  throw_if_interrupted("diagnosing (looking for causes); no report was written");
  return runs;
}

// Where forward selection stands between steps.
struct SelectionState {
  CvRun current;                    // cross-validation of the model in hand
  GlobalFit full;                   // its full-data fit
  std::vector<CandidateTrial> solo;  // step 1's trials: each candidate alone on the baseline
};

// One step of forward selection: tries every candidate not yet in the model whose requirement is
// met, judges them, applies the selection rules and adds the best accepted one. Returns false when
// the selection ends (nothing left to try or nothing accepted).
bool selection_step(const DiagnoseProblem& p, const SelectionOptions& o, const std::vector<int>& all, int step,
                    SelectionState& s, Diagnosis& dg) {
  throw_if_interrupted("diagnosing (looking for causes); no report was written");
  std::vector<int> todo;
  for (int c = 0; c < static_cast<int>(p.candidates().size()); ++c)
    if (!s.full.state.has(c) && requirement_met(p, s.full.state, c)) todo.push_back(c);
  if (todo.empty()) return false;
  // Once the model in hand nearly fits and what it misses is one shape shared by every item,
  // tissue causes must exceed the noise floor (SelectionOptions: instrument mismatch).
  NoiseFloor floor = dg.floor;
  floor.instrument_mismatch = nearly_fits(lack_of_fit(p, s.full, dg.floor), o);
  std::vector<CvRun> runs = cross_validate_candidates(p, o, dg.folds, s.current, todo, step);
  std::vector<CandidateTrial> trials;
  for (size_t k = 0; k < todo.size(); ++k) trials.push_back(judge(p, todo[k], s.current, std::move(runs[k]), dg.folds, floor, o));
  if (step == 1) s.solo = trials;
  // The rules that compare this step's trials with each other (selection_policies.h), in order.
  // accept_unlike_any_instrument only while nothing is named yet: after a cause is in, a leftover below the floor is as likely
  // the imperfect shape of that cause (a skewed band fitted by the log-normal one drew in
  // bacterial porphyrin in 1 of 10 independent runs when this applied at every step).
  if (s.full.state.causes.empty()) accept_unlike_any_instrument(p, trials, o.z);
  prefer_single_width(p, trials, o.z);
  reject_dominated_global_broadening(p, trials);
  const CandidateTrial* aside = hold_to_set_aside(p, trials, o.z);
  if (aside) dg.set_aside.push_back(describe_set_aside(p, *aside, step));
  int best = best_accepted(trials);
  if (aside && best >= 0) dg.set_aside.back().instead = p.candidates()[trials[best].candidate].id;
  dg.steps.push_back(trials);
  if (best < 0) return false;
  CandidateTrial& t = dg.steps.back()[best];
  CauseResult cr;
  cr.candidate = t.candidate;
  cr.step = step;
  cr.trial = t;
  if (const CandidateTrial* solo = solo_trial(s.solo, t.candidate)) cr.solo = *solo;
  if (!o.report_by.empty()) {
    cr.by_report = breakdown(p, s.current, t.cv, o.report_by, nullptr);
    if (cr.solo.candidate >= 0) cr.solo_by_report = breakdown(p, dg.baseline_cv, cr.solo.cv, o.report_by, nullptr);
  }
  ModelState next = with_cause(p, s.full.state, t.candidate);
  s.full = fit_global(p, next, all, static_cast<int>(next.causes.size()) - 1);
  s.current = t.cv;
  dg.causes.push_back(std::move(cr));
  return true;
}

// Spread of the leave-one-group-out fits of every flattened parameter (group jackknife); zeros
// when no cause was accepted.
std::vector<double> group_jackknife(const Diagnosis& dg, const GlobalFit& full, const CvRun& current) {
  const int G = dg.folds.count();
  std::vector<double> x = flatten(full.state);
  std::vector<double> jack(x.size(), 0.0);
  if (dg.causes.empty()) return jack;
  std::vector<std::vector<double>> fx;
  for (auto& s : current.fold_states) fx.push_back(flatten(s));
  for (size_t j = 0; j < x.size(); ++j) {
    double m = 0;
    for (auto& v : fx) m += v[j];
    m /= G;
    double s = 0;
    for (auto& v : fx) s += (v[j] - m) * (v[j] - m);
    jack[j] = std::sqrt((G - 1.0) / G * s);
  }
  return jack;
}

// Parameters and their uncertainty: the full-data fit, with the larger of the group jackknife
// (spread of the leave-one-group-out fits) and the curvature error inflated for correlated
// residuals; then each cause's derived parameters, bounds reached and plain words.
void estimate_cause_parameters(const DiagnoseProblem& p, const std::vector<int>& all, Diagnosis& dg) {
  const GlobalFit& full = dg.final_fit;
  std::vector<double> jack = group_jackknife(dg, full, dg.final_cv);
  double inflate = 1.0 / std::sqrt(std::max(dg.floor.n_eff_ratio, 1e-3));
  auto fits_all = p.evaluate(full.state, all);
  size_t off = p.baseline_params().size();
  for (size_t k = 0; k < full.state.causes.size(); ++k) {
    auto& a = full.state.causes[k];
    CauseResult& cr = dg.causes[k];
    cr.theta = a.theta;
    for (size_t j = 0; j < a.theta.size(); ++j) {
      double sc = full.se[off + j] * inflate;
      cr.se_curvature.push_back(sc);
      cr.se_jackknife.push_back(jack[off + j]);
      cr.uncertainty.push_back(std::max(sc, jack[off + j]));
    }
    off += a.theta.size();
    const CandidateSpec& c = p.candidates()[a.candidate];
    cr.derived = p.derived_params(c, fits_all, all);
    cr.at_bound = final_params_at_bound(c, cr.theta);
    cr.words = p.plain_words(c, cr.theta, cr.uncertainty, cr.derived);
  }
}

// The one-line verdict: the set-aside cause first, then the causes found (or the closest
// candidate when none), then the instrument-mismatch note.
std::string verdict_text(const DiagnoseProblem& p, const Diagnosis& dg) {
  std::string verdict;
  if (dg.causes.empty()) {
    const CandidateTrial* b = nullptr;
    if (!dg.steps.empty())
      for (auto& t : dg.steps[0])
        if (!b || t.mean_gain - t.threshold > b->mean_gain - b->threshold) b = &t;
    verdict = "no significant effect: no candidate cause improves the held-out prediction by more than the noise allows";
    if (!dg.set_aside.empty()) verdict = "no cause accepted";  // the set-aside one did; the verdict opens with it
    else if (b)
      verdict += " (closest: " + p.candidates()[b->candidate].id + ", gain " + verdict_number(b->mean_gain) + " vs threshold " +
                 verdict_number(b->threshold) + ")";
  } else {
    verdict = std::to_string(dg.causes.size()) + " cause(s) found:";
    for (auto& c : dg.causes) verdict += " " + p.candidates()[c.candidate].id;
  }
  verdict = set_aside_verdict(p, dg.set_aside) + verdict;
  if (dg.instrument_mismatch)
    verdict += "; instrument mismatch: the baseline misses by only " + verdict_number(dg.baseline_lack_of_fit) + " x the noise floor and " +
               verdict_number(100 * dg.common_shape_share) +
               " % of its residual is one shape shared by every item (tissue causes had to exceed the noise floor)";
  return verdict;
}

}  // namespace

Diagnosis diagnose(const DiagnoseProblem& p, const SelectionOptions& o) {
  Diagnosis dg;
  dg.options = o;
  dg.folds = make_folds(p, o.group_columns);
  require_two_folds(dg.folds, o);
  auto all = all_items(p);
  fit_baseline(p, o, all, dg);

  SelectionState s{dg.baseline_cv, dg.baseline_fit, {}};
  for (int step = 1; step <= o.max_causes; ++step)
    if (!selection_step(p, o, all, step, s, dg)) break;
  dg.final_fit = s.full;
  dg.final_cv = s.current;
  estimate_cause_parameters(p, all, dg);

  dg.instrument_check = instrument_checks(p, dg, o.check_by);
  dg.rmse_baseline_heldout = dg.baseline_cv.rmse();
  dg.rmse_extended_heldout = dg.final_cv.rmse();
  GroupGain overall = group_gain(p, dg.baseline_cv, dg.final_cv, all, "all");
  dg.ve_baseline_heldout = overall.ve_before;
  dg.ve_extended_heldout = overall.ve_after;
  if (!o.report_by.empty()) dg.by_report = breakdown(p, dg.baseline_cv, dg.final_cv, o.report_by, nullptr);
  dg.by_fold = breakdown(p, dg.baseline_cv, dg.final_cv, "", &dg.folds);
  dg.verdict = verdict_text(p, dg);
  return dg;
}

CauseEstimate cause_estimate(const DiagnoseProblem& p, const CauseResult& c, const std::string& name) {
  const auto& spec = p.candidates()[c.candidate];
  for (size_t k = 0; k < spec.params.size(); ++k)
    if (spec.params[k].name == name) return {c.theta[k], c.uncertainty[k]};
  for (const auto& d : c.derived)
    if (d.name == name) return {d.value, d.uncertainty};
  return {};
}

}  // namespace ofl
