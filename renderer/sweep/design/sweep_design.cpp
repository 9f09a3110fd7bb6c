#include "renderer/sweep/design/sweep_design.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ofl {

std::vector<std::vector<int>> full_grid(const std::vector<int>& sizes) {
  size_t total = 1;
  for (int s : sizes) total *= static_cast<size_t>(std::max(s, 0));
  std::vector<std::vector<int>> out;
  out.reserve(total);
  std::vector<int> idx(sizes.size(), 0);
  for (size_t k = 0; k < total; ++k) {
    out.push_back(idx);
    for (int d = int(sizes.size()) - 1; d >= 0; --d) {  // odometer: last dimension fastest
      if (++idx[d] < sizes[d]) break;
      idx[d] = 0;
    }
  }
  return out;
}

std::vector<std::vector<double>> latin_hypercube(int n, int dims, uint64_t seed) {
  std::vector<std::vector<double>> u(n, std::vector<double>(dims, 0.0));
  SplitMix64 rng(seed * 0x2545f4914f6cdd1dULL + 0x1234567ULL);
  std::vector<int> perm(n);
  for (int d = 0; d < dims; ++d) {
    for (int i = 0; i < n; ++i) perm[i] = i;
    for (int i = n - 1; i > 0; --i) std::swap(perm[i], perm[rng.below(uint64_t(i) + 1)]);  // Fisher-Yates
    for (int i = 0; i < n; ++i) u[i][d] = (perm[i] + rng.uniform()) / n;
  }
  return u;
}

std::vector<DesignPoint> make_design(const SweepSpec& spec) {
  const auto& ps = spec.parameters;
  std::vector<DesignPoint> out;
  if (spec.design.type == DesignSpec::Type::kGrid) {
    std::vector<int> sizes;
    for (auto& p : ps) sizes.push_back(p.levels());
    auto grid = full_grid(sizes);
    for (size_t k = 0; k < grid.size(); ++k) {
      DesignPoint d;
      d.index = int(k);
      d.level = grid[k];
      for (size_t i = 0; i < ps.size(); ++i) d.values.push_back(ps[i].values[grid[k][i]]);
      out.push_back(std::move(d));
    }
    return out;
  }
  const int n = spec.design.points;
  auto u = latin_hypercube(n, int(ps.size()), spec.design.seed);
  for (int k = 0; k < n; ++k) {
    DesignPoint d;
    d.index = k;
    for (size_t i = 0; i < ps.size(); ++i) {
      const auto& p = ps[i];
      double x = u[k][i];
      if (p.range) {
        const ParamRange& r = *p.range;
        double v = r.log ? std::exp(std::log(r.min) + x * (std::log(r.max) - std::log(r.min))) : r.min + x * (r.max - r.min);
        if (r.integer) {
          // Integers: stratify over the integers of the range, so each is equally likely.
          long long lo = std::llround(std::ceil(r.min - 1e-9)), hi = std::llround(std::floor(r.max + 1e-9));
          long long m = std::min(hi, lo + static_cast<long long>(std::floor(x * double(hi - lo + 1))));
          d.values.push_back(m);
        } else {
          d.values.push_back(v);
        }
        d.level.push_back(-1);
      } else {
        int l = std::min(p.levels() - 1, int(std::floor(x * p.levels())));
        d.values.push_back(p.values[l]);
        d.level.push_back(l);
      }
    }
    out.push_back(std::move(d));
  }
  return out;
}

std::string value_text(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char b[32];
    std::snprintf(b, sizeof b, "%.6g", v.get<double>());
    return b;
  }
  return v.dump();
}

std::string point_label(const SweepSpec& spec, const DesignPoint& p) {
  std::string s;
  for (size_t i = 0; i < spec.parameters.size(); ++i)
    s += (i ? " " : "") + spec.parameters[i].name + "=" + value_text(p.values[i]);
  return s;
}

}  // namespace ofl
