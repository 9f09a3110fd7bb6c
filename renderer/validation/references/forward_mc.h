// An independent forward photon Monte Carlo of layered tissue with positions, the reference for
// the spatial transport (docs/layered-tissue.md, "Lateral transport"). Written from the physics
// here, not from the renderer's stack walk: photons enter through a smooth top (Fresnel, Snell),
// fly exponential distances through plane layers whose optical properties may differ inside a
// vertical cylinder (a lesion of radius a around the z axis: "layers plus a cylinder of other
// properties"), and at each collision scatter (Henyey-Greenstein) with probability mu_s / mu_t or
// are absorbed (analog). An absorbed excitation photon leaves one fluorescence photon of weight
// kappa(ex) / mu_a(ex) (kappa the layer's re-emission coefficient: the chance that the absorption
// re-emits), at an emission bin drawn from the layer's re-emission matrix, isotropic; it is followed
// the same way but does not fluoresce again. Every photon that leaves through
// the top is tallied by where it leaves (distance from the z axis), its wavelength bin and whether
// it is fluorescence, in all directions and within two cones around the normal.
//
// The light leaving along the normal itself (what a camera straight above sees) is estimated
// without a cone, by a local estimate: at every scattering and at every fluorescence birth the
// photon adds its weight times the chance density (per unit solid angle in air) that it turns
// straight up and gets out, at the point above it. That chance is the phase function towards the
// normal (Henyey-Greenstein, or 1 / 4 pi for an emission) times the vertical transmission of the
// column above, with the incoherent inter-reflections between index steps summed in closed form
// (normal-incidence Fresnel at each step), times (n_air / n_layer)^2 for the solid angle's change
// through the faces. Summed over photons it is the radiance along the normal per unit incident
// flux, so pi * sum / photons is the radiance factor of uniform light (docs/layered-tissue.md,
// "How it was checked").
//
// Lengths are millimetres; layers are given per column (outside / inside the cylinder) on the
// renderer's wavelength grid (from its stack tables, which are inputs here, not the walk). The
// two columns must have the same refractive index at every depth (the cylinder wall does not
// refract); their layer boundaries may differ.
#pragma once
#include <cstdint>
#include <vector>

#include "renderer/render/material/stack_tables.h"

namespace ofl {

struct ForwardColumn {
  const StackTables* st = nullptr;  // layers (mua, mus, g, ior, fluorophores) on the grid
};

struct ForwardSetup {
  ForwardColumn outside, inside;    // inside: the cylinder (ignored when radius_mm <= 0)
  double radius_mm = 0;             // cylinder radius
  int n = 0;                        // wavelength bins
  // The source: photons at bins drawn from `source` (photon shape on the grid), entering at polar
  // angle theta_deg (in air, azimuth 0), at the origin (pencil) or uniformly over the square
  // [-half_mm, half_mm]^2 (uniform illumination).
  std::vector<double> source;
  double theta_deg = 0;
  double half_mm = 0;
  // Uniform illumination, importance-sampled: half of the photons land uniformly on the square, half
  // uniformly on the disc of this radius around the axis, each weighted by the uniform density over
  // the mixture's (0: all on the square).
  double focus_mm = 0;
  bool fluorescence = true;
  // Tally rings: exits at distance r from the axis go to the ring [edges[i], edges[i+1]).
  std::vector<double> ring_edges;
  double cone_cos = 0.9;            // "within the cone": leaving with cos(theta) above this, in air
  double narrow_cos = 0.97;         // a second, narrower cone (nearer what a camera straight above sees)
};

struct ForwardTally {
  long long photons = 0;
  // [ring * n + bin] photon weight leaving (all directions / within the cone / within the narrow
  // cone), elastic and fluorescent; and the local estimate of the weight per unit solid angle (in
  // air) leaving along the normal.
  std::vector<double> elastic, fluor, elastic_cone, fluor_cone, elastic_narrow, fluor_narrow, elastic_normal, fluor_normal;
  void add(const ForwardTally& o);
};

// Runs `photons` photons (seeded by (seed, photon index), so batches are independent and
// reproducible whatever the thread count).
ForwardTally run_forward_mc(const ForwardSetup& s, long long photons, uint64_t seed);

}  // namespace ofl
