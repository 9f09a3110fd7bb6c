#include "renderer/numerics/nnls.h"

#include <cmath>
#include <vector>

namespace ofl {

namespace {
// Least squares on the passive columns only; the others are zero.
Eigen::VectorXd solve_passive(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const std::vector<bool>& passive) {
  int n = static_cast<int>(A.cols());
  std::vector<int> idx;
  for (int j = 0; j < n; ++j)
    if (passive[j]) idx.push_back(j);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  if (idx.empty()) return z;
  Eigen::MatrixXd Ap(A.rows(), static_cast<Eigen::Index>(idx.size()));
  for (size_t k = 0; k < idx.size(); ++k) Ap.col(static_cast<Eigen::Index>(k)) = A.col(idx[k]);
  Eigen::VectorXd zp = Ap.colPivHouseholderQr().solve(b);
  for (size_t k = 0; k < idx.size(); ++k) z[idx[k]] = zp[static_cast<Eigen::Index>(k)];
  return z;
}
}  // namespace

NnlsResult nnls(const Eigen::MatrixXd& A0, const Eigen::VectorXd& b, int max_iterations) {
  const int n = static_cast<int>(A0.cols());
  NnlsResult r;
  r.x = Eigen::VectorXd::Zero(n);
  if (n == 0) {
    r.rss = b.squaredNorm();
    return r;
  }
  // Scale columns to unit norm so that the tolerance means the same for every column
  // (fluorophore columns and a leak column can differ by orders of magnitude).
  Eigen::VectorXd scale(n);
  Eigen::MatrixXd A = A0;
  for (int j = 0; j < n; ++j) {
    double s = A.col(j).norm();
    scale[j] = s > 0 ? s : 0.0;
    if (s > 0) A.col(j) /= s;
  }
  if (max_iterations <= 0) max_iterations = 3 * n + 10;
  std::vector<bool> passive(n, false);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const double tol = 1e-10 * std::max(1.0, b.norm());
  int it = 0;
  for (;;) {
    Eigen::VectorXd w = A.transpose() * (b - A * x);
    int best = -1;
    double wmax = tol;
    for (int j = 0; j < n; ++j)
      if (!passive[j] && scale[j] > 0 && w[j] > wmax) { wmax = w[j]; best = j; }
    if (best < 0) break;
    if (++it > max_iterations) { r.converged = false; break; }
    passive[best] = true;
    // Inner loop: step toward the unconstrained passive solution until it is feasible.
    for (int inner = 0; inner < 3 * n + 10; ++inner) {
      Eigen::VectorXd z = solve_passive(A, b, passive);
      bool feasible = true;
      for (int j = 0; j < n; ++j)
        if (passive[j] && z[j] <= 0) { feasible = false; break; }
      if (feasible) { x = z; break; }
      double alpha = 1.0;
      for (int j = 0; j < n; ++j)
        if (passive[j] && z[j] <= 0) {
          double d = x[j] - z[j];
          if (d > 0) alpha = std::min(alpha, x[j] / d);
        }
      x += alpha * (z - x);
      for (int j = 0; j < n; ++j)
        if (passive[j] && x[j] <= 1e-14) { passive[j] = false; x[j] = 0; }
    }
  }
  for (int j = 0; j < n; ++j) {
    if (x[j] < 0) x[j] = 0;
    r.x[j] = scale[j] > 0 ? x[j] / scale[j] : 0.0;
    if (x[j] > 0) ++r.active;
  }
  r.rss = (A0 * r.x - b).squaredNorm();
  r.iterations = it;
  return r;
}

}  // namespace ofl
