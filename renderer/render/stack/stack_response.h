// The tabulated response of a layer stack (transport "table", docs/layered-tissue.md "Cost"):
// the position-free BSDF of everything below the top interface's specular reflection, as a
// function of the cosines of the viewing and light directions (azimuth-averaged) and of the
// wavelength pair, filled once per material at scene load by the stack's own random walk
// (renderer/render/stack/stack_walk.h), which stays the reference.
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
//
// What a table holds and how it is looked up (StackResponse, StackResponseOptions) is
// stack_response_table.h, which the on-disk cache (stack_response_cache.h) reads and writes too.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "renderer/render/material/material_tables.h"
#include "renderer/render/stack/stack_response_table.h"

namespace ofl {

// Why a stack cannot be tabulated (empty: it can).
std::string stack_response_unsupported(const StackTables& st, const MaterialTables& mt);

// The stack's depth-resolved fluence for light incident at fixed cosines: what the table's
// fluorescence is built from, for callers that weight depth themselves (diagnose's layered_tissue
// cause, renderer/diagnose/spectra/layered_site.h). Same walks as the fill (photon mode, entering through the
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
