// The heaviest tests under `make sanitize` (CMake -DOFL_SANITIZE=ON defines OFL_SANITIZED): an
// AddressSanitizer + UBSan build runs the Monte Carlo and fitting code many times slower, and the
// whole suite must still finish within the CI limit. Those tests run the same checks on less work
// there: fewer samples per pixel (tolerances of Monte Carlo errors widened by sqrt of the factor,
// the standard error's growth), fewer random data sets (the same claim on each one). Nothing is
// skipped. The normal build is unchanged: every function returns its argument there.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace ofl::test {

#ifdef OFL_SANITIZED
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

// Samples per pixel divided by `factor` under sanitizers (at least 1).
inline int sanitized_spp(int spp, int factor = 4) { return kSanitized ? std::max(1, spp / factor) : spp; }

// A tolerance on a Monte Carlo error of a run whose samples were divided by `factor`: the standard
// error grows by sqrt(factor).
inline double sanitized_tolerance(double tol, int factor = 4) { return kSanitized ? tol * std::sqrt(double(factor)) : tol; }

// The first `n` items of a list of cases (seeds, data sets) under sanitizers, all of them otherwise.
template <class T>
std::vector<T> sanitized_cases(std::vector<T> all, std::size_t n) {
  if (kSanitized && all.size() > n) all.resize(n);
  return all;
}

}  // namespace ofl::test
