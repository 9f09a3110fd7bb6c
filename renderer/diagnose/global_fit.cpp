#include "renderer/diagnose/global_fit.h"

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

}  // namespace

GlobalFit fit_global(const DiagnoseProblem& p, ModelState start, const std::vector<int>& items, int grid_cause,
                     const GlobalFitOptions& opt) {
  GlobalFit out;
  auto specs = state_param_specs(p, start);
  std::vector<double> x = flatten(start);
  for (size_t j = 0; j < x.size(); ++j) x[j] = clampv(x[j], specs[j]);
  ModelState s = start;
  unflatten(s, x);

  // Start grid for one cause: the product of its parameters' start lists.
  if (grid_cause >= 0 && grid_cause < static_cast<int>(s.causes.size())) {
    size_t off = p.baseline_params().size();
    for (int k = 0; k < grid_cause; ++k) off += s.causes[k].theta.size();
    auto& cps = p.candidates()[s.causes[grid_cause].candidate].params;
    std::vector<std::vector<double>> lists;
    size_t combos = 1;
    for (auto& ps : cps) {
      lists.push_back(ps.starts.empty() || ps.tie_start >= 0 ? std::vector<double>{ps.init} : ps.starts);
      combos *= lists.back().size();
    }
    if (combos > 1) {
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
  }

  Stacked cur = residuals(p, s, items);
  double f = cur.r.squaredNorm();
  const int np = static_cast<int>(x.size());
  Eigen::MatrixXd J(cur.r.size(), np);
  double lambda = 1e-3;
  int it = 0;
  auto jacobian = [&]() {
    for (int j = 0; j < np; ++j) {
      double h = specs[j].fd_step;
      std::vector<double> xh = x;
      xh[j] = x[j] + h;
      if (xh[j] > specs[j].hi) { xh[j] = x[j] - h; h = -h; }
      ModelState sh = s;
      unflatten(sh, xh);
      J.col(j) = (residuals(p, sh, items).r - cur.r) / h;  // d r / d x
    }
  };
  if (np > 0) {
    for (it = 0; it < opt.max_iterations; ++it) {
      jacobian();
      Eigen::MatrixXd H = J.transpose() * J;
      Eigen::VectorXd g = J.transpose() * cur.r;  // gradient of 0.5|r|^2 is J^T r
      bool improved = false;
      double f_new = f;
      for (int tries = 0; tries < 12; ++tries) {
        Eigen::MatrixXd A = H;
        // A parameter the items do not constrain (zero column: a per-subject parameter of a subject
        // outside them) stays where it is.
        for (int j = 0; j < np; ++j) A(j, j) += H(j, j) > 0 ? lambda * H(j, j) : 1.0;
        Eigen::VectorXd d = A.ldlt().solve(-g);
        std::vector<double> xn = x;
        for (int j = 0; j < np; ++j) xn[j] = clampv(x[j] + d[j], specs[j]);
        ModelState sn = s;
        unflatten(sn, xn);
        Stacked rn = residuals(p, sn, items);
        f_new = rn.r.squaredNorm();
        if (std::isfinite(f_new) && f_new < f) {
          x = xn;
          s = sn;
          cur = std::move(rn);
          lambda = std::max(lambda / 4, 1e-9);
          improved = true;
          break;
        }
        lambda *= 8;
      }
      if (!improved) break;
      double rel = (f - f_new) / std::max(f, 1e-300);
      f = f_new;
      if (rel < opt.rel_tolerance) break;
    }
    if (opt.uncertainties) jacobian();
  }
  out.state = s;
  out.rss = f;
  out.n_obs = cur.r.size();
  out.local_dofs = cur.local;
  out.iterations = it;
  out.se.assign(np, 0.0);
  if (!opt.uncertainties) return out;
  out.jtj = np > 0 ? Eigen::MatrixXd(J.transpose() * J) : Eigen::MatrixXd();
  if (np > 0) {
    double dof = std::max<double>(1, static_cast<double>(out.n_obs - np - out.local_dofs));
    double s2 = f / dof;
    Eigen::MatrixXd cov = out.jtj.completeOrthogonalDecomposition().pseudoInverse() * s2;
    for (int j = 0; j < np; ++j) out.se[j] = std::sqrt(std::max(0.0, cov(j, j)));
  }
  return out;
}

}  // namespace ofl
