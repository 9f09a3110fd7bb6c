// What the spatial transport of a layered material looks up at render time, prepared once per
// render from its lateral profiles (stack_profiles.h), the LED spectra and the layers' re-emission
// (docs/layered-tissue.md, "Lateral transport"):
// - the elastic exit profiles, cut at the search radius (renormalised, so no light is lost);
// - per LED spectrum group, the depth weights of direct fluorescence: how much of the light
//   re-emitted at `em` comes from each depth slice Z, for a viewer and a light at the profiles'
//   cosines, c(Z) = sum over fine depth bins b in Z of [(n_ambient / n_b)^2 Phi(b; mu_o, em) / dz_b]
//   x [sum_ex sigma_b(em <- ex) S(ex) Phi(b; mu_i, ex)] (the depth integrand of the position-free
//   table's fluorescence, renderer/render/stack/stack_response.h, at the profiles' exact cosines);
// - per LED group, the excitation leg: the lateral distribution, in each slice, of the LED light
//   the fluorophores absorb there (the slice's legs of the excitation bins, weighted by the LED's
//   photons, the fluence and the fluorophores' absorption);
// - the search radius: where every profile of the stack has reached 99.9 % of its mass.
#pragma once
#include <memory>
#include <vector>

#include "renderer/render/material/material_tables.h"
#include "renderer/render/spatial/stack_profiles.h"

namespace ofl {

struct SpatialStack {
  std::shared_ptr<const StackProfiles> prof;
  int n = 0, C = 0, Z = 0, G = 0;
  double search_mm = 0;  // probe sphere radius; every profile below is zero beyond it
  // Elastic exit profiles cut at search_mm: [(c * n + wl) * R_el + j].
  std::vector<float> el_mass, el_cdf;
  // Fluence legs cut at search_mm: [((c * n + wl) * Z + z) * R_leg + j].
  std::vector<float> leg_mass, leg_cdf;
  // Direct-fluorescence depth weights c(Z): [(((g * C + co) * C + ci) * n + em) * Z + z] and their
  // sums over Z at [((g * C + co) * C + ci) * n + em].
  std::vector<float> slice_c, slice_total;
  // Excitation legs per LED group: [((g * C + c) * Z + z) * R_leg + j]; filled for every stack (one
  // that does not fluoresce still attenuates the excitation light crossing it), and the LED light's
  // fluence in each slice (mm per unit irradiance, the photon-weighted mean over the LED's bins) at
  // [(g * C + c) * Z + z].
  std::vector<float> ex_mass, ex_cdf, ex_fluence;
  // The same three as densities per unit area (mass / ring area, 1/mm^2), for evaluation.
  std::vector<float> el_dens, leg_dens, ex_dens;
  bool fluorescent = false;

  const RadialRings& el_rings() const { return prof->elastic_rings; }
  const RadialRings& leg_rings() const { return prof->leg_rings; }
  size_t el_at(int c, int wl) const { return (size_t(c) * n + wl) * prof->elastic_rings.rings; }
  size_t leg_at(int c, int wl, int z) const { return ((size_t(c) * n + wl) * Z + z) * prof->leg_rings.rings; }
  size_t ex_at(int g, int c, int z) const { return ((size_t(g) * C + c) * Z + z) * prof->leg_rings.rings; }
  size_t slice_at(int g, int co, int ci, int em) const { return ((size_t(g) * C + co) * C + ci) * n + em; }

  using Cosines = StackProfiles::CosineWeights;
  Cosines cosines(double mu) const { return prof->weights(mu); }
  // Elastic exit density (1/mm^2) at r for a viewer at cosine mu_o (interpolated between cosines);
  // the second form takes the ring of r (el_rings().ring_of(r), >= 0), shared by several lanes.
  double elastic_density(const Cosines& co, int wl, double r_mm) const;
  double elastic_density_in(const Cosines& co, int wl, int ring) const {
    return co.w[0] * el_dens[el_at(co.c[0], wl) + ring] + (co.w[1] > 0 ? co.w[1] * el_dens[el_at(co.c[1], wl) + ring] : 0.0);
  }
  // Direct-fluorescence depth weights c(z) for every slice (out[Z]) and one slice, and their sum over
  // the slices, interpolated in both cosines (viewer co, light ci).
  void slice_weights(int g, const Cosines& co, const Cosines& ci, int em, double* out) const;
  double slice_weight(int g, const Cosines& co, const Cosines& ci, int em, int z) const;
  double slice_sum(int g, const Cosines& co, const Cosines& ci, int em) const;
  // The emission leg's density (1/mm^2) at r in slice z, viewer cosines co; the excitation leg's for
  // LED group g at light cosines ci.
  double emission_density(const Cosines& co, int em, int z, double r_mm) const;
  double emission_density_in(const Cosines& co, int em, int z, int ring) const {
    return co.w[0] * leg_dens[leg_at(co.c[0], em, z) + ring] +
           (co.w[1] > 0 ? co.w[1] * leg_dens[leg_at(co.c[1], em, z) + ring] : 0.0);
  }
  double excitation_density(int g, const Cosines& ci, int z, double r_mm) const;
  // The fluence in slice z (mm per unit irradiance) of the viewer's emission-band light (the
  // emission leg's amplitude) and of LED group g's light (the excitation leg's); with the densities
  // above they are the legs' Green's functions, which a crossing of regions compares between
  // materials (renderer/render/integrator/spatial_vertex.cpp, fluorescent_crossing).
  double emission_fluence(const Cosines& co, int em, int z) const;
  double excitation_fluence(int g, const Cosines& ci, int z) const;
};

// Prepares the spatial tables of a stack (null when it has no profiles to build them from).
// `light_shapes` are the renderer's LED photon shapes per group; with none, one flat group stands in.
std::shared_ptr<const SpatialStack> build_spatial_stack(const StackTables& st, std::shared_ptr<const StackProfiles> prof,
                                                        const std::vector<std::vector<float>>& light_shapes);

}  // namespace ofl
