// The material every surface has at render time: a Lambertian base described by an albedo
// matrix A = diag(R) + sum_k c_k Phi_k * dlambda (reflectance plus fluorophores, optionally seen
// through a blood layer), an optional wet dielectric coating on top (GGX + Fresnel), and an
// optional Lambertian emission. The JSON types that build it (lambertian, fluorescent, coated,
// tissue, teeth) each live in their own file in this folder; see material_parser.h.
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include "materials/description/layered.h"

namespace ofl {

// The renderer keeps a surface point's concentrations in a fixed array of this size; a material
// with more fluorophores is an input error (materials/fluorescent.cpp).
constexpr int kMaxFluorophoresPerMaterial = 16;

// One fluorophore of a material: which EEM (index into Scene::eems), its concentration (the
// photon albedo at the fluorophore's excitation peak for library entries) and an optional
// grayscale texture that multiplies the concentration (index into Scene::textures).
struct FluorophoreLayer {
  int eem = -1;
  double concentration = 0;
  int texture = -1;
  double texture_offset = 0;  // concentration factor = max(0, offset + scale * texel)
  double texture_scale = 1;
  std::string name;
  double factor(float texel) const { return std::max(0.0, texture_offset + texture_scale * texel); }
};

// Wet-tissue coating: a smooth-to-rough dielectric interface (GGX microfacets, Fresnel) over the
// base; see coated.h for the energy-conserving layering.
struct Coating {
  bool enabled = false;
  double ior = 1.33;        // water-like mucus layer
  double roughness = 0.15;  // GGX alpha
};

// Part of a "regions" material: where the mask texture exceeds the threshold, or within a sphere
// (a disc where the sphere cuts a surface), the surface is made of another scene material
// (materials/regions.cpp).
struct MaterialRegion {
  int texture = -1;  // the mask; -1 for a sphere region
  double threshold = 0.5;
  // Per texel of the mask, the distance in texels to the nearest texel on the other side of the
  // threshold (side_distance_texels): the walk's bound on where the region can end.
  std::vector<float> side_distance;
  bool sphere = false;
  double centre_m[3] = {0, 0, 0};
  double radius_m = 0;
  std::string material_name;
  int material = -1;  // resolved after every material is read
};

struct Material {
  std::string name;
  std::vector<double> reflectance;        // R on the grid, 0..1
  std::vector<FluorophoreLayer> fluorophores;
  // An absorbing layer over the base (blood): transmittance on the way out (emission) and on the
  // way in (excitation); the albedo matrix becomes diag(T_out) A diag(T_in). Empty = none.
  std::vector<double> layer_out, layer_in;
  Coating coating;
  std::vector<double> emission;           // Lambertian emitted radiance, W sr^-1 m^-2 nm^-1, empty = none
  int reflectance_texture = -1;           // optional grayscale map multiplying R
  // Layered tissue (materials/description/layered.h): when enabled the material is the stack; `reflectance` and
  // `fluorophores` then describe its opaque base (StackBottom::kBase) and are otherwise unused.
  LayerStack stack;
  // A "regions" material only dispatches: the first region whose mask exceeds its threshold at the
  // surface point gives the material there, else `regions_base`.
  std::vector<MaterialRegion> regions;
  std::string regions_base_name;
  int regions_base = -1;
  bool dispatches() const { return regions_base >= 0 || !regions_base_name.empty(); }
};

}  // namespace ofl
