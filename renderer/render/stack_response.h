// The tabulated response of a layer stack (transport "table", docs/layered-tissue.md "Cost"):
// the position-free BSDF of everything below the top interface's specular reflection, as a
// function of the cosines of the viewing and light directions (azimuth-averaged) and of the
// wavelength pair, filled once per material at scene load by the stack's own random walk
// (renderer/render/stack_walk.h), which stays the reference.
//
// How it is filled. For each of `nodes` incidence cosines mu_k = (k + 0.5) / nodes and each group
// of eight adjacent wavelength bins, `photons` walks enter the stack through the top interface
// (photon mode, no re-radiation; light reflected by the top is the closed-form specular lobe and is
// not counted) from cosines drawn around mu_k in proportion to the node's tent weight times mu, the
// same weight the exits are deposited with, so that the elastic table of a reciprocal stack is
// symmetric (a Galerkin projection on the tents). Each walk gives
// - the elastic part: where it leaves through the top, its weight spread over the two nearest
//   cosine nodes (linear "tent" weights, the same ones evaluation interpolates with);
// - the fluence: at every collision each lane's weight (a track-length estimate) is added to the
//   depth bin of the collision.
// Fluorescence is isotropic and position-free, so it factorises through depth exactly: with
// Phi(z; mu, lambda) the fluence at depth z per unit irradiance incident from mu, the camera-side
// importance of a source at depth z is (n_ambient / n(z))^2 Phi(z; mu_o, em) (radiance / n^2 is
// invariant), and
//   f(mu_o, mu_i, ex -> em) = 1 / (4 pi) sum_layers integral (n_a / n_l)^2 Phi(z; mu_o, em)
//                              sigma_l(em <- ex) Phi(z; mu_i, ex) dz
// (radiance out per unit irradiance in: Phi is per unit irradiance on the surface plane).
// This counts fluorescence excited by LED light and by elastically scattered light at any depth,
// but not fluorescence excited by fluorescence (a second re-radiation), which the walk has.
//
// Walks are seeded by (node, wavelength group) only, so the table is the same whatever the number
// of threads. Stacks whose fluorophores have textures, or with a fluorescent base, are not
// tabulated (the walk runs): the table holds one point's response.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "renderer/render/render_tables.h"

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
  // The on-disk cache folder (renderer/render/stack_response_cache.h); empty: no cache.
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

// Why a stack cannot be tabulated (empty: it can).
std::string stack_response_unsupported(const StackTables& st, const MaterialTables& mt);

// The stack's depth-resolved fluence for light incident at fixed cosines: what the table's
// fluorescence is built from, for callers that weight depth themselves (diagnose's layered_tissue
// cause, renderer/diagnose/layered_site.h). Same walks as the fill (photon mode, entering through the
// top interface, similarity after opt.similarity_after collisions), launched at exactly mu, seeded
// by (cosine, wavelength group), so the result does not depend on the number of threads.
struct StackFluence {
  int n = 0;                        // wavelength bins
  std::vector<double> mu;           // incidence cosines
  std::vector<double> lo, hi;       // depth bins, mm
  std::vector<int> layer;           // layer of each depth bin
  // [(c * n + wl) * bins + b]: integral of the fluence over depth bin b, per unit irradiance on the
  // surface plane at cosine mu[c] (mm; divide by the bin's width for the mean fluence). Bins from
  // opt.used_bins on are zero.
  std::vector<double> phi;
  int bins() const { return int(lo.size()); }
  const double* at(int c, int wl) const { return &phi[(size_t(c) * n + wl) * bins()]; }
};
StackFluence stack_fluence(const StackTables& st, const MaterialTables& mt, int n, const std::vector<double>& mu,
                           const StackResponseOptions& opt);

std::shared_ptr<const StackResponse> build_stack_response(const StackTables& st, const MaterialTables& mt, int n,
                                                          const std::vector<std::vector<float>>& light_shapes,
                                                          const StackResponseOptions& opt);

}  // namespace ofl
