#include "renderer/diagnose/selection/global_fit.h"

#include <algorithm>
#include <cmath>

namespace ofl {

std::vector<ParamSpec> state_param_specs(const DiagnoseProblem& p, const ModelState& s) {
  std::vector<ParamSpec> v = p.baseline_params();
  for (auto& a : s.causes) {
    auto& c = p.candidates()[a.candidate].params;
    v.insert(v.end(), c.begin(), c.end());
  }
  return v;
}

std::vector<double> flatten(const ModelState& s) {
  std::vector<double> x = s.base_theta;
  for (auto& a : s.causes) x.insert(x.end(), a.theta.begin(), a.theta.end());
  return x;
}

void unflatten(ModelState& s, const std::vector<double>& x) {
  size_t k = 0;
  for (double& v : s.base_theta) v = x[k++];
  for (auto& a : s.causes)
    for (double& v : a.theta) v = x[k++];
}

ModelState baseline_state(const DiagnoseProblem& p) {
  ModelState s;
  for (auto& b : p.baseline_params()) s.base_theta.push_back(b.init);
  return s;
}

ModelState with_cause(const DiagnoseProblem& p, ModelState s, int c) {
  ActiveCause a;
  a.candidate = c;
  for (auto& ps : p.candidates()[c].params) a.theta.push_back(ps.init);
  s.causes.push_back(a);
  return s;
}

namespace {

struct Stacked {
  Eigen::VectorXd r;
  int local = 0;
};

Stacked residuals(const DiagnoseProblem& p, const ModelState& s, const std::vector<int>& items) {
  auto fits = p.evaluate(s, items);
  Eigen::Index n = 0;
  for (auto& f : fits) n += f.residual.size();
  Stacked out;
  out.r.resize(n);
  Eigen::Index k = 0;
  for (auto& f : fits) {
    out.r.segment(k, f.residual.size()) = f.residual;
    k += f.residual.size();
    out.local += f.local_dofs;
  }
  return out;
}

double clampv(double v, const ParamSpec& ps) { return std::min(ps.hi, std::max(ps.lo, v)); }

// Start grid for one cause: the product of its parameters' start lists; x and s move to the start
// with the smallest residual when there is more than one.
void best_grid_start(const DiagnoseProblem& p, const std::vector<int>& items, int grid_cause, std::vector<double>& x,
                     ModelState& s) {
  if (grid_cause < 0 || grid_cause >= static_cast<int>(s.causes.size())) return;
  size_t off = p.baseline_params().size();
  for (int k = 0; k < grid_cause; ++k) off += s.causes[k].theta.size();
  auto& cps = p.candidates()[s.causes[grid_cause].candidate].params;
  std::vector<std::vector<double>> lists;
  size_t combos = 1;
  for (auto& ps : cps) {
    lists.push_back(ps.starts.empty() || ps.tie_start >= 0 ? std::vector<double>{ps.init} : ps.starts);
    combos *= lists.back().size();
  }
  if (combos <= 1) return;
  double best = std::numeric_limits<double>::infinity();
  std::vector<double> bestx = x;
  for (size_t m = 0; m < combos; ++m) {
    size_t q = m;
    std::vector<double> xt = x;
    for (size_t j = 0; j < lists.size(); ++j) {
      xt[off + j] = clampv(lists[j][q % lists[j].size()], cps[j]);
      q /= lists[j].size();
    }
    for (size_t j = 0; j < lists.size(); ++j)
      if (cps[j].tie_start >= 0) xt[off + j] = clampv(xt[off + static_cast<size_t>(cps[j].tie_start)], cps[j]);
    ModelState st = s;
    unflatten(st, xt);
    double f = residuals(p, st, items).r.squaredNorm();
    if (f < best) { best = f; bestx = xt; }
  }
  x = bestx;
  unflatten(s, x);
}

// Where the least-squares iteration stands: parameters, their state, residuals, |r|^2 and the
// Jacobian last computed.
struct LmPoint {
  std::vector<double> x;
  ModelState s;
  Stacked cur;
  double f = 0;
  Eigen::MatrixXd J;
};

// Forward-difference Jacobian d r / d x at the current point (a backward step at an upper bound).
void jacobian(const DiagnoseProblem& p, const std::vector<int>& items, const std::vector<ParamSpec>& specs, LmPoint& at) {
  const int np = static_cast<int>(at.x.size());
  for (int j = 0; j < np; ++j) {
    double h = specs[j].fd_step;
    std::vector<double> xh = at.x;
    xh[j] = at.x[j] + h;
    if (xh[j] > specs[j].hi) { xh[j] = at.x[j] - h; h = -h; }
    ModelState sh = at.s;
    unflatten(sh, xh);
    at.J.col(j) = (residuals(p, sh, items).r - at.cur.r) / h;
  }
}

// Bounded Levenberg-Marquardt from `at` until no step improves or the relative gain falls below
// the tolerance; returns the iterations done.
int levenberg_marquardt(const DiagnoseProblem& p, const std::vector<int>& items, const std::vector<ParamSpec>& specs,
                        const GlobalFitOptions& opt, LmPoint& at) {
  const int np = static_cast<int>(at.x.size());
  double lambda = 1e-3;
  int it = 0;
  for (it = 0; it < opt.max_iterations; ++it) {
    jacobian(p, items, specs, at);
    Eigen::MatrixXd H = at.J.transpose() * at.J;
    Eigen::VectorXd g = at.J.transpose() * at.cur.r;  // gradient of 0.5|r|^2 is J^T r
    bool improved = false;
    double f_new = at.f;
    for (int tries = 0; tries < 12; ++tries) {
      Eigen::MatrixXd A = H;
      // A parameter the items do not constrain (zero column: a per-subject parameter of a subject
      // outside them) stays where it is.
      for (int j = 0; j < np; ++j) A(j, j) += H(j, j) > 0 ? lambda * H(j, j) : 1.0;
      Eigen::VectorXd d = A.ldlt().solve(-g);
      std::vector<double> xn = at.x;
      for (int j = 0; j < np; ++j) xn[j] = clampv(at.x[j] + d[j], specs[j]);
      ModelState sn = at.s;
      unflatten(sn, xn);
      Stacked rn = residuals(p, sn, items);
      f_new = rn.r.squaredNorm();
      if (std::isfinite(f_new) && f_new < at.f) {
        at.x = xn;
        at.s = sn;
        at.cur = std::move(rn);
        lambda = std::max(lambda / 4, 1e-9);
        improved = true;
        break;
      }
      lambda *= 8;
    }
    if (!improved) break;
    double rel = (at.f - f_new) / std::max(at.f, 1e-300);
    at.f = f_new;
    if (rel < opt.rel_tolerance) break;
  }
  return it;
}

}  // namespace

GlobalFit fit_global(const DiagnoseProblem& p, ModelState start, const std::vector<int>& items, int grid_cause,
                     const GlobalFitOptions& opt) {
  GlobalFit out;
  auto specs = state_param_specs(p, start);
  LmPoint at;
  at.x = flatten(start);
  for (size_t j = 0; j < at.x.size(); ++j) at.x[j] = clampv(at.x[j], specs[j]);
  at.s = start;
  unflatten(at.s, at.x);
  best_grid_start(p, items, grid_cause, at.x, at.s);

  at.cur = residuals(p, at.s, items);
  at.f = at.cur.r.squaredNorm();
  const int np = static_cast<int>(at.x.size());
  at.J.resize(at.cur.r.size(), np);
  int it = 0;
  if (np > 0) {
    it = levenberg_marquardt(p, items, specs, opt, at);
    if (opt.uncertainties) jacobian(p, items, specs, at);
  }
  out.state = at.s;
  out.rss = at.f;
  out.n_obs = at.cur.r.size();
  out.local_dofs = at.cur.local;
  out.iterations = it;
  out.se.assign(np, 0.0);
  if (!opt.uncertainties) return out;
  // Standard errors from the curvature: the pseudo-inverse of J^T J times the residual variance.
  out.jtj = np > 0 ? Eigen::MatrixXd(at.J.transpose() * at.J) : Eigen::MatrixXd();
  if (np > 0) {
    double dof = std::max<double>(1, static_cast<double>(out.n_obs - np - out.local_dofs));
    double s2 = at.f / dof;
    Eigen::MatrixXd cov = out.jtj.completeOrthogonalDecomposition().pseudoInverse() * s2;
    for (int j = 0; j < np; ++j) out.se[j] = std::sqrt(std::max(0.0, cov(j, j)));
  }
  return out;
}

}  // namespace ofl
