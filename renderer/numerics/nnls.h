// Non-negative least squares: minimise |A x - b|^2 subject to x >= 0 (Lawson & Hanson 1974,
// active-set method). diagnose uses it for the per-spectrum fluorophore amplitudes, which are
// concentrations and light levels and so cannot be negative. Problems there are small (a few
// hundred rows, at most a few dozen columns), so each passive-set solve is a fresh column-pivoted QR.
#pragma once
#include <Eigen/Dense>

namespace ofl {

struct NnlsResult {
  Eigen::VectorXd x;  // >= 0
  double rss = 0;     // |A x - b|^2
  int active = 0;     // number of strictly positive entries (the fit's local degrees of freedom)
  int iterations = 0;
  bool converged = true;
};

// Columns that are all zero get x = 0. `max_iterations` bounds the outer loop (3 n by default).
NnlsResult nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int max_iterations = 0);

}  // namespace ofl
