// The design of a sweep: which combinations of parameter values are run. A full grid takes every
// combination of every parameter's levels (the last parameter varies fastest). A Latin hypercube
// of n points splits each parameter's range into n equal strata and puts exactly one point in each
// stratum of each parameter, pairing strata across parameters by independent random permutations:
// n points cover every one-dimensional range evenly however many parameters there are. Continuous
// ranges are sampled at a random position inside the stratum; lists (and variants) are indexed by
// the stratum, so each of L levels gets n / L points (+-1). Deterministic from the design seed, on
// every machine (own generator, no std:: distributions whose output is implementation defined).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/sweep/design/sweep_spec.h"

namespace ofl {

struct DesignPoint {
  int index = 0;                         // position in the design: the point's identity
  std::vector<nlohmann::json> values;    // one per parameter, as written into the documents
  std::vector<int> level;                // index into the parameter's levels; -1: a continuous sample
};

std::vector<DesignPoint> make_design(const SweepSpec& spec);

// Every combination of sizes[0] x sizes[1] x ... indices, the last dimension fastest.
std::vector<std::vector<int>> full_grid(const std::vector<int>& sizes);
// n x dims samples in [0, 1): in every dimension exactly one sample in each [k/n, (k+1)/n).
std::vector<std::vector<double>> latin_hypercube(int n, int dims, uint64_t seed);

// "name=value name=value" for logs.
std::string point_label(const SweepSpec& spec, const DesignPoint& p);
// A value as a short string ("0.05", "true", "no_coating").
std::string value_text(const nlohmann::json& v);

// SplitMix64 (Steele, Lea, Flood 2014): small, fast, the same sequence everywhere.
struct SplitMix64 {
  uint64_t state;
  explicit SplitMix64(uint64_t seed) : state(seed) {}
  uint64_t next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return (next() >> 11) * 0x1.0p-53; }  // [0, 1)
  uint64_t below(uint64_t n) {  // [0, n), unbiased (Lemire's multiply-and-reject)
    unsigned __int128 m = static_cast<unsigned __int128>(next()) * n;
    uint64_t lo = static_cast<uint64_t>(m);
    if (lo < n) {
      uint64_t t = (0 - n) % n;
      while (lo < t) {
        m = static_cast<unsigned __int128>(next()) * n;
        lo = static_cast<uint64_t>(m);
      }
    }
    return static_cast<uint64_t>(m >> 64);
  }
};

}  // namespace ofl
