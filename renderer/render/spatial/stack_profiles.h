// How far light travels sideways in a layer stack: the radial profiles the spatial transport
// ("transport": "spatial", docs/layered-tissue.md "Lateral transport") samples and evaluates,
// tabulated once per stack by the stack's own random walk with the lateral position tracked.
//
// What is tabulated, for light entering through the top at each of a few exact incidence cosines
// (photon mode, the same launch as the position-free table's fill, renderer/render/stack/stack_fill.h):
// - the elastic exit profile P(r; mu, lambda): where the diffusely reflected light leaves, as ring
//   masses around the entry point (renderer/render/spatial/radial_profile.h), with the diffuse
//   reflectance itself. By reciprocity it is also where light leaving toward a viewer at cosine mu
//   entered, which is how the renderer uses it (the separable approximation: the profile depends on
//   one direction's cosine, the directional factor is the position-free table's);
// - the fluence legs K(rho; mu, lambda, Z): in each of a fixed set of depth slices Z (the same
//   absolute depths for every stack, so that a lesion and the healthy tissue beside it speak of the
//   same slices), the lateral distribution of the fluence of the entering light. Fluorescence
//   emitted at depth z is excited by light that spread sideways on its way down (the excitation
//   leg, at the excitation wavelength) and spreads again on its way up (the emission leg, at the
//   emission wavelength; by reciprocity the fluence of light entering from the viewer), and in a
//   laterally uniform stack the two displacements are independent given z: the fluorescence profile
//   is their convolution, summed over depth;
// - the depth-resolved fluence Phi(z; mu, lambda) on the position-free table's fine depth bins, from
//   which the renderer weights the depth slices (how much fluorescence comes from each).
//
// The fill is deterministic (walks seeded by cosine, wavelength group and walk) and cached on disk
// beside the position-free tables (renderer/render/stack/stack_response_cache.h).
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "renderer/render/material/material_tables.h"
#include "renderer/render/spatial/radial_profile.h"

namespace ofl {

struct StackProfileOptions {
  std::vector<double> cosines = {1.0, 0.75, 0.5, 0.25};  // launch cosines, descending
  int photons = 20000;                                  // walks per cosine and wavelength group
  // As StackResponseOptions::similarity_after, but later: lateral spread and the reflectance of dark,
  // forward-scattering slabs need more of the exact phase (at 60 MCML's mucosa_450 loses 1.2 % of
  // its diffuse reflectance, at 200 0.5 %; benchmarks/mcml_radial/README.md).
  int similarity_after = 200;
  RadialRings elastic_rings{20.0, 96};
  RadialRings leg_rings{20.0, 64};
  uint64_t seed = 0x50524F46ULL;
  int used_bins = 0;  // bins from this one up are not walked; 0 = all
  // Count in the elastic profile the light that leaves without having met a turbid layer (reflected
  // inside a clear film). The renderer does (the position-free table counts it too); MCML counts it
  // as specular reflection, so its comparison does not.
  bool clear_exits = true;
  std::filesystem::path cache_dir;  // empty: no cache
  std::string label;                // what the progress line calls the fill
};

// The fixed depth slices of the fluence legs (mm below the top face of the stack): finer near the
// surface, where the excitation light is absorbed; the last one ends at the depth cap.
const std::vector<double>& leg_depth_edges();

struct StackProfiles {
  int n = 0;
  std::vector<double> cosines;
  RadialRings elastic_rings, leg_rings;
  std::vector<double> depth_edges;  // leg_depth_edges()
  // Elastic exit profiles: [(c * n + wl) * R_el + j] ring mass and running sum; rd[c * n + wl] the
  // diffuse reflectance (all radii) and kept[c * n + wl] the part of it inside r_max.
  std::vector<float> elastic_mass, elastic_cdf, rd, kept;
  // Fluence legs: [((c * n + wl) * Z + z) * R_leg + j] ring mass and running sum per depth slice;
  // leg_fluence[(c * n + wl) * Z + z] the slice's fluence (mm, per unit irradiance).
  std::vector<float> leg_mass, leg_cdf, leg_fluence;
  // Depth-resolved fluence on the fine bins of renderer/render/stack/stack_fill.h (DepthBins):
  // [(c * n + wl) * B + b], mm per unit irradiance on the surface plane.
  std::vector<float> fine_fluence;
  int fine_bins = 0;
  long long walks = 0;
  double build_seconds = 0;
  bool from_cache = false;
  std::vector<std::string> warnings;

  int slices() const { return int(depth_edges.size()) - 1; }
  const float* elastic_cdf_at(int c, int wl) const { return &elastic_cdf[(size_t(c) * n + wl) * elastic_rings.rings]; }
  const float* elastic_mass_at(int c, int wl) const { return &elastic_mass[(size_t(c) * n + wl) * elastic_rings.rings]; }
  size_t leg_index(int c, int wl, int z) const { return ((size_t(c) * n + wl) * slices() + z) * leg_rings.rings; }
  // Interpolation between the tabulated cosines: two indices and weights (clamped at the ends).
  struct CosineWeights {
    int c[2] = {0, 0};
    double w[2] = {1, 0};
  };
  CosineWeights weights(double mu) const;
};

// The cache entry name of a stack's profiles (32 hex digits).
std::string stack_profile_key(const StackTables& st, const MaterialTables& mt, int n, const StackProfileOptions& opt);

// Fills (or reads back from the cache) the profiles of a stack on an n-bin grid.
std::shared_ptr<const StackProfiles> build_stack_profiles(const StackTables& st, const MaterialTables& mt, int n,
                                                          const StackProfileOptions& opt);

}  // namespace ofl
