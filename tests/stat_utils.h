// Statistics helpers for tests: Pearson's chi-square goodness-of-fit test of a sampler against
// its density (bins with small expectation merged), with the p-value from the Wilson-Hilferty
// normal approximation of the chi-square distribution.
#pragma once
#include <cmath>
#include <vector>

namespace ofl::test {

struct ChiSquare {
  double statistic = 0;
  int dof = 0;
  double p_value = 1;
};

// observed[i] counts and expected[i] = n * probability of bin i.
inline ChiSquare chi_square(const std::vector<double>& observed, const std::vector<double>& expected) {
  std::vector<double> o, e;
  double acc_o = 0, acc_e = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    acc_o += observed[i];
    acc_e += expected[i];
    if (acc_e >= 5) { o.push_back(acc_o); e.push_back(acc_e); acc_o = acc_e = 0; }
  }
  if (acc_e > 0 || acc_o > 0) {
    if (e.empty()) { o.push_back(acc_o); e.push_back(acc_e); }
    else { o.back() += acc_o; e.back() += acc_e; }
  }
  ChiSquare r;
  for (size_t i = 0; i < o.size(); ++i) {
    if (e[i] <= 0) { r.statistic += o[i] > 0 ? 1e30 : 0; continue; }
    r.statistic += (o[i] - e[i]) * (o[i] - e[i]) / e[i];
  }
  r.dof = std::max(1, int(o.size()) - 1);
  double k = r.dof;
  double z = (std::cbrt(r.statistic / k) - (1 - 2 / (9 * k))) / std::sqrt(2 / (9 * k));
  r.p_value = 0.5 * std::erfc(z / std::sqrt(2.0));
  return r;
}

}  // namespace ofl::test
