#include "renderer/diagnose/cross_validation.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "renderer/core/error.h"
#include "renderer/core/progress.h"

namespace ofl {

namespace {

std::string key_of(const DiagnoseProblem& p, int i, const std::vector<std::string>& cols) {
  std::string k;
  for (auto& c : cols) k += (k.empty() ? "" : ", ") + c + "=" + p.condition(i, c);
  return k;
}

std::string fmtg(double v) {
  char b[64];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
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
                     bool parallel) {
  const int G = folds.count();
  CvRun run;
  run.heldout.resize(p.num_items());
  run.item_mse.assign(p.num_items(), 0.0);
  run.fold_states.resize(G);
  auto one = [&](int g) {
    std::vector<int> train, test;
    for (int i = 0; i < p.num_items(); ++i) (folds.of_item[i] == g ? test : train).push_back(i);
    GlobalFit fit = fit_global(p, starts[g], train, grid_cause);
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

CandidateTrial judge(const DiagnoseProblem& p, int cand, const CvRun& before, CvRun after, const Folds& folds,
                     const NoiseFloor& nf, const SelectionOptions& o) {
  CandidateTrial t;
  t.candidate = cand;
  const int M = p.num_items();
  const int dp = cand >= 0 ? p.candidates()[cand].local_dofs : 0;
  std::vector<double> d(M), mu(M);
  double sd2 = 0;
  for (int i = 0; i < M; ++i) {
    double n = static_cast<double>(std::max<Eigen::Index>(1, after.heldout[i].residual.size()));
    double neff = std::max(1.0, n * nf.n_eff_ratio);
    d[i] = before.item_mse[i] - after.item_mse[i];
    mu[i] = dp * nf.variance / neff;
    sd2 += 2.0 * std::max(dp, 1) * nf.variance * nf.variance / (neff * neff);
  }
  double mean = 0, optimism = 0;
  for (int i = 0; i < M; ++i) { mean += d[i]; optimism += mu[i]; }
  mean /= M;
  optimism /= M;
  double var = 0;
  for (int i = 0; i < M; ++i) var += (d[i] - mean) * (d[i] - mean);
  t.se_items = M > 1 ? std::sqrt(var / (M - 1) / M) : 0;
  t.sd_noise = std::sqrt(sd2 / M) / std::sqrt(static_cast<double>(M));
  t.mean_gain = mean;
  t.optimism = optimism;
  t.threshold = optimism + o.z * std::max(t.sd_noise, t.se_items);
  t.folds = folds.count();
  for (int g = 0; g < folds.count(); ++g) {
    double s = 0;
    int n = 0;
    for (int i = 0; i < M; ++i)
      if (folds.of_item[i] == g) { s += d[i] - mu[i]; ++n; }
    if (n && s > 0) ++t.folds_improved;
  }
  t.rmse_before = before.rmse();
  t.rmse_after = after.rmse();
  bool gain_ok = mean > t.threshold;
  bool folds_ok = t.folds_improved > o.min_fold_fraction * t.folds;
  double effect = std::sqrt(std::max(0.0, mean - optimism));
  bool size_ok = effect >= o.min_effect_to_noise * nf.rmse;
  t.accepted = gain_ok && folds_ok && size_ok;
  if (t.accepted)
    t.verdict = "held-out gain beats the noise";
  else if (!gain_ok)
    t.verdict = "held-out gain " + fmtg(mean) + " below the threshold " + fmtg(t.threshold);
  else if (!folds_ok)
    t.verdict = "improves only " + std::to_string(t.folds_improved) + " of " + std::to_string(t.folds) + " held-out groups";
  else
    t.verdict = "significant but negligible: effect RMS " + fmtg(effect) + " < " + fmtg(o.min_effect_to_noise) + " x noise floor";
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

}  // namespace

Diagnosis diagnose(const DiagnoseProblem& p, const SelectionOptions& o) {
  Diagnosis dg;
  dg.options = o;
  dg.folds = make_folds(p, o.group_columns);
  if (dg.folds.count() < 2) {
    std::string cols;
    for (auto& c : o.group_columns) cols += (cols.empty() ? "" : ",") + c;
    throw InputError("groups", cols.empty() ? "(none)" : cols,
                     "cross-validation needs at least two groups, the data have one (" +
                         (dg.folds.names.empty() ? std::string("no items") : dg.folds.names[0]) + ")");
  }
  auto all = all_items(p);
  const int G = dg.folds.count();

  ModelState base = baseline_state(p);
  dg.baseline_fit = fit_global(p, base, all);
  dg.floor = estimate_noise_floor(p, o.replicate_columns, p.evaluate(dg.baseline_fit.state, all));
  if (dg.floor.variance <= 0) {
    dg.floor.variance = dg.baseline_fit.rss / std::max<long>(1, dg.baseline_fit.n_obs);
    dg.floor.rmse = std::sqrt(dg.floor.variance);
    dg.floor.source = "baseline residual (no replicates and no other noise estimate; conservative)";
  }
  std::vector<ModelState> starts(G, base);
  dg.baseline_cv = cross_validate(p, starts, -1, dg.folds, o.parallel);

  CvRun current = dg.baseline_cv;
  GlobalFit full = dg.baseline_fit;
  std::vector<CandidateTrial> solo;
  const int C = static_cast<int>(p.candidates().size());
  for (int step = 1; step <= o.max_causes; ++step) {
    std::vector<int> todo;
    for (int c = 0; c < C; ++c)
      if (!full.state.has(c)) todo.push_back(c);
    if (todo.empty()) break;
    std::vector<CvRun> runs(todo.size());
    ProgressBar bar("diagnose: cause " + std::to_string(step) + ", candidates", static_cast<int64_t>(todo.size()));
    auto run_one = [&](size_t k) {
      std::vector<ModelState> st;
      for (int g = 0; g < G; ++g) st.push_back(with_cause(p, current.fold_states[g], todo[k]));
      runs[k] = cross_validate(p, st, static_cast<int>(st[0].causes.size()) - 1, dg.folds, false);
      bar.advance();
    };
    if (o.parallel)
      tbb::parallel_for(size_t(0), todo.size(), run_one);
    else
      for (size_t k = 0; k < todo.size(); ++k) run_one(k);
    std::vector<CandidateTrial> trials;
    for (size_t k = 0; k < todo.size(); ++k) trials.push_back(judge(p, todo[k], current, std::move(runs[k]), dg.folds, dg.floor, o));
    if (step == 1) solo = trials;
    int best = -1;
    for (size_t k = 0; k < trials.size(); ++k)
      if (trials[k].accepted &&
          (best < 0 || trials[k].mean_gain - trials[k].optimism > trials[best].mean_gain - trials[best].optimism))
        best = static_cast<int>(k);
    dg.steps.push_back(trials);
    if (best < 0) break;
    CandidateTrial& t = dg.steps.back()[best];
    CauseResult cr;
    cr.candidate = t.candidate;
    cr.step = step;
    cr.trial = t;
    for (auto& s : solo)
      if (s.candidate == t.candidate) cr.solo = s;
    if (!o.report_by.empty()) {
      cr.by_report = breakdown(p, current, t.cv, o.report_by, nullptr);
      cr.solo_by_report = breakdown(p, dg.baseline_cv, cr.solo.cv, o.report_by, nullptr);
    }
    ModelState next = with_cause(p, full.state, t.candidate);
    full = fit_global(p, next, all, static_cast<int>(next.causes.size()) - 1);
    current = t.cv;
    dg.causes.push_back(std::move(cr));
  }
  dg.final_fit = full;
  dg.final_cv = current;

  // Parameters and their uncertainty: the full-data fit, with the larger of the group jackknife
  // (spread of the leave-one-group-out fits) and the curvature error inflated for correlated
  // residuals.
  std::vector<double> x = flatten(full.state);
  std::vector<double> jack(x.size(), 0.0);
  if (!dg.causes.empty()) {
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
  }
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
    cr.words = p.plain_words(c, cr.theta, cr.uncertainty, cr.derived);
  }

  dg.rmse_baseline_heldout = dg.baseline_cv.rmse();
  dg.rmse_extended_heldout = dg.final_cv.rmse();
  GroupGain overall = group_gain(p, dg.baseline_cv, dg.final_cv, all, "all");
  dg.ve_baseline_heldout = overall.ve_before;
  dg.ve_extended_heldout = overall.ve_after;
  if (!o.report_by.empty()) dg.by_report = breakdown(p, dg.baseline_cv, dg.final_cv, o.report_by, nullptr);
  dg.by_fold = breakdown(p, dg.baseline_cv, dg.final_cv, "", &dg.folds);
  if (dg.causes.empty()) {
    const CandidateTrial* b = nullptr;
    if (!dg.steps.empty())
      for (auto& t : dg.steps[0])
        if (!b || t.mean_gain - t.threshold > b->mean_gain - b->threshold) b = &t;
    dg.verdict = "no significant effect: no candidate cause improves the held-out prediction by more than the noise allows";
    if (b)
      dg.verdict += " (closest: " + p.candidates()[b->candidate].id + ", gain " + fmtg(b->mean_gain) + " vs threshold " +
                    fmtg(b->threshold) + ")";
  } else {
    dg.verdict = std::to_string(dg.causes.size()) + " cause(s) found:";
    for (auto& c : dg.causes) dg.verdict += " " + p.candidates()[c.candidate].id;
  }
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
