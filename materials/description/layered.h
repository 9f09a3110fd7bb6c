// Layered tissue: a stack of plane-parallel scattering, absorbing and fluorescing layers under an
// optional wet coating, for the JSON type "layered_tissue" (materials/layered_tissue.cpp, format in
// docs/scene-format.md, physics in docs/layered-tissue.md). Everything here is tabulated on the
// transport grid; lengths are millimetres and coefficients 1/mm.
//
// How a library fluorophore becomes a volume quantity. A library EEM Phi(em, ex) is a surface
// photon albedo per nm of emission; its photon albedo a(ex) = integral Phi(em, ex) d em peaks at
// a_peak at the excitation peak. A layer names the fluorophore with its absorption coefficient at
// that peak, mua_peak (1/mm), and its quantum yield QY. Then
//   absorption      mua_f(ex)        = mua_peak * a(ex) / a_peak                      (1/mm)
//   re-emission     sigma_f(em <- ex) = mua_peak * QY * Phi(em, ex) / a_peak   (1/mm per nm of em)
// so that integral sigma_f(em <- ex) d em = QY * mua_f(ex): each absorbed photon is re-emitted
// with probability QY (less the part the Stokes mask removes), with the library's emission shape
// for that excitation wavelength, isotropically. Energy is conserved by construction when
// 0 <= QY <= 1; the parser checks that and that every coefficient is finite and non-negative.
#pragma once
#include <limits>
#include <string>
#include <vector>

namespace ofl {

constexpr int kMaxStackLayers = 8;
constexpr int kMaxLayerFluorophores = 8;

struct LayerFluorophore {
  std::string name;
  int eem = -1;                   // index into Scene::eems (the library/file EEM on the grid)
  double mua_peak_per_mm = 0;     // absorption coefficient at the excitation peak
  double quantum_yield = 0;
  int texture = -1;               // optional grayscale map: factor = max(0, offset + scale * texel)
  double texture_offset = 0, texture_scale = 1;
};

struct TissueLayer {
  std::string name;
  double thickness_mm = 0;        // infinity for a semi-infinite last layer
  double ior = 1.37;
  double g = 0.9;                 // Henyey-Greenstein anisotropy
  std::vector<double> mua;        // absorption by chromophores (blood, baseline, others), 1/mm, on the grid
  std::vector<double> mus;        // scattering coefficient (not reduced), 1/mm, on the grid
  std::vector<LayerFluorophore> fluorophores;
  bool semi_infinite() const { return thickness_mm == std::numeric_limits<double>::infinity(); }
};

// How light is carried inside the stack at render time (docs/layered-tissue.md, "Cost").
enum class StackTransport {
  kTable,  // a response table filled once by the walk at scene load (renderer/render/stack/stack_response.h)
  kWalk,    // the random walk at every shading point (the reference)
  kSpatial, // the table for the directional part and lateral profiles for where light comes back out
            // (renderer/render/spatial/, docs/layered-tissue.md "Lateral transport")
  kVolume   // the walk at every shading point with its lateral position tracked, in the material under
            // it (regions resolved under every step): the reference for kSpatial across regions
            // (renderer/render/integrator/layered_bsdf.h, docs/layered-tissue.md "The volume walk")
};

// What lies under the last layer.
enum class StackBottom {
  kSemiInfinite,  // the last layer goes on forever
  kOpen,          // a clear half-space of index below_ior: light leaving through it is transmitted
  kBase           // an opaque Lambertian surface: the Material's reflectance and fluorophores
};

struct LayerStack {
  bool enabled = false;
  double ambient_ior = 1.0;       // medium above (air)
  double top_roughness = 0;       // GGX alpha of the top interface; 0 = smooth (Fresnel mirror)
  std::vector<TissueLayer> layers;  // top to bottom; a wet coating is the first, clear layer
  StackBottom bottom = StackBottom::kSemiInfinite;
  double below_ior = 1.0;         // kOpen only
  StackTransport transport = StackTransport::kTable;
  int table_photons = 0;          // walks per incidence cosine and wavelength group; 0 = the default
  int table_similarity_after = -1; // collisions before the table's walks scatter by similarity; 0 = never, -1 = the default
  int profile_photons = 0;        // spatial: walks per cosine and wavelength group filling the profiles; 0 = the default
};

}  // namespace ofl
