// The tabulated response of a layer stack as plain data (transport "table"): the options it is
// filled with and the tables it holds, with their lookups, interpolated between the cosine nodes.
// How it is filled, and why it holds what it does, is stack_response.h (whose .cpp also defines
// the lookups); the on-disk cache (stack_response_cache.h) stores and reads it.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

struct StackResponseOptions {
  int nodes = 12;         // incidence cosines
  int photons = 2000;     // walks per node and wavelength group
  // Average the elastic part with its transpose. Off by default: the rough top's lossless
  // resampling (dielectric_interface.h) divides by the valid fraction of the incident direction,
  // which is not reciprocal, and the walk's convention (viewer = launch direction) is kept.
  bool symmetrize = false;
  uint64_t seed = 0x5354414BULL;
  int used_bins = 0;      // bins from this one up are not walked (the film never samples them); 0 = all
  // After this many collisions a walk scatters by the similarity relation (isotropic, mus (1 - g);
  // StackWalker::with_similarity_after); 0 = the exact phase function throughout. At 60 the fill is
  // 3.1-3.6x faster and the table moves by at most 1.3 % (benchmarks/results.d/40_layered_cost.md).
  int similarity_after = 60;
  // The on-disk cache folder (renderer/render/stack/stack_response_cache.h); empty: no cache.
  std::filesystem::path cache_dir;
  std::string label;      // what the progress line calls the table (the material's name)
};

struct StackResponse {
  int nodes = 0, n = 0;
  // [(o * nodes + i) * n + wl]: the elastic BSDF (1/sr) at cosine nodes o (viewer) and i (light).
  std::vector<float> elastic;
  // [((o * nodes + i) * n + em) * n + ex]: the fluorescent BSDF per excitation bin (1/sr, the bin
  // width included, as the surface EEM tables), ex < em; and per row its sum and normalised CDF.
  std::vector<float> fluor, fluor_sum, fluor_cdf;
  // [group][(o * nodes + i) * n + em]: sum over ex of fluor times the LED group's photon shape.
  std::vector<std::vector<float>> direct;
  double build_seconds = 0;  // of the fill (also when read back from the cache)
  long long walks = 0;
  bool from_cache = false;
  std::vector<std::string> warnings;  // the cache's (an entry ignored, a table not stored)

  // Linear interpolation between the nodes (held constant outside the first and last).
  struct Weights {
    int k[2] = {0, 0};
    float w[2] = {1, 0};
  };
  Weights weights(double mu) const;
  size_t cell(int o, int i) const { return size_t(o) * nodes + i; }
  // Interpolated at cosines with weights a (viewer) and b (light).
  float elastic_at(const Weights& a, const Weights& b, int wl) const;
  float fluor_sum_at(const Weights& a, const Weights& b, int em) const;
  float direct_at(int group, const Weights& a, const Weights& b, int em) const;
  // An excitation bin for a lane at `em`, in proportion to the interpolated row; u uniform in [0, 1).
  int sample_excitation(const Weights& a, const Weights& b, int em, double u1, float u2) const;
  // Directional albedo (elastic part) at node o and bin wl: integral of f cos over the hemisphere.
  double elastic_albedo(int o, int wl) const;
};

}  // namespace ofl
