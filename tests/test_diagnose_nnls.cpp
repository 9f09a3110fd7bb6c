// Diagnose: the non-negative least squares solver against brute force over every active set.
#include <gtest/gtest.h>

#include <random>

#include "renderer/numerics/nnls.h"

using namespace ofl;

namespace {
// Best feasible unconstrained solution over all subsets of columns (exact NNLS for small n).
double brute_force_rss(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(A.cols());
  double best = b.squaredNorm();
  for (int mask = 1; mask < (1 << n); ++mask) {
    std::vector<int> idx;
    for (int j = 0; j < n; ++j)
      if (mask & (1 << j)) idx.push_back(j);
    Eigen::MatrixXd As(A.rows(), static_cast<Eigen::Index>(idx.size()));
    for (size_t k = 0; k < idx.size(); ++k) As.col(static_cast<Eigen::Index>(k)) = A.col(idx[k]);
    Eigen::VectorXd x = As.colPivHouseholderQr().solve(b);
    if (x.minCoeff() < 0) continue;
    best = std::min(best, (As * x - b).squaredNorm());
  }
  return best;
}
}  // namespace

TEST(DiagnoseNnls, MatchesBruteForceOnRandomProblems) {
  // 200 random problems with 2-6 columns, some of which want negative coefficients: the solver's
  // residual equals the best over all active sets to 1e-9 (relative) and x >= 0.
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0, 1);
  for (int t = 0; t < 200; ++t) {
    int n = 2 + t % 5, m = 12 + t % 7;
    Eigen::MatrixXd A(m, n);
    Eigen::VectorXd b(m);
    for (int i = 0; i < m; ++i) {
      b[i] = N(rng);
      for (int j = 0; j < n; ++j) A(i, j) = N(rng) * (j + 1);  // columns of different scale
    }
    NnlsResult r = nnls(A, b);
    ASSERT_TRUE(r.converged);
    EXPECT_GE(r.x.minCoeff(), 0.0);
    double bf = brute_force_rss(A, b);
    EXPECT_NEAR(r.rss, bf, 1e-9 * std::max(1.0, bf)) << "problem " << t;
    // KKT: the gradient is zero on positive coefficients and points outward on zero ones.
    Eigen::VectorXd w = A.transpose() * (b - A * r.x);
    for (int j = 0; j < n; ++j) {
      if (r.x[j] > 0) EXPECT_NEAR(w[j], 0.0, 1e-8 * (1 + A.col(j).norm() * b.norm()));
      else EXPECT_LE(w[j], 1e-8 * (1 + A.col(j).norm() * b.norm()));
    }
  }
}

TEST(DiagnoseNnls, RecoversExactNonNegativeMixAndIgnoresZeroColumns) {
  Eigen::MatrixXd A(5, 3);
  A << 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 1, 0, 2, 0, 0;  // third column all zero
  Eigen::VectorXd x0(3);
  x0 << 2.0, 0.5, 0.0;
  NnlsResult r = nnls(A, A * x0);
  EXPECT_NEAR(r.x[0], 2.0, 1e-12);
  EXPECT_NEAR(r.x[1], 0.5, 1e-12);
  EXPECT_EQ(r.x[2], 0.0);
  EXPECT_EQ(r.active, 2);
  EXPECT_NEAR(r.rss, 0.0, 1e-20);
}
