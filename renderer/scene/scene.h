// A scene ready to render: everything from the scene file tabulated on the transport grid.
// load_scene() reads the JSON file (format documented in docs/scene-format.md); every error names
// the file and the JSON pointer of the offending field and is an InputError (exit code 2).
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "materials/description/material.h"
#include "renderer/core/files/json_node.h"
#include "renderer/scene/camera_spec.h"
#include "renderer/scene/led_light.h"
#include "renderer/image/texture.h"
#include "renderer/mesh/geometry/triangle_mesh.h"
#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

// Output bands of the film: centres min..max every step, each band step wide.
struct BandSet {
  double min_nm = 400, max_nm = 700, step_nm = 10;
  int size() const { return static_cast<int>(std::lround((max_nm - min_nm) / step_nm)) + 1; }
  double centre(int b) const { return min_nm + step_nm * b; }
};

struct IntegratorSpec {
  int spp = 16;
  int max_depth = 5;          // scattering events per path
  int rr_start_depth = 1;     // Russian roulette before continuing from this vertex on (0-based: 1 = the second)
  uint64_t seed = 1;
  WavelengthGrid grid;
  BandSet bands;
  enum class DirectExcitation { kDeterministic, kSampled };
  DirectExcitation direct_excitation = DirectExcitation::kDeterministic;
  // Which LED next-event estimation goes to at a surface point: weighed by what each LED can give
  // that point (renderer/render/trace/light_choice.h), or by power alone (the older estimator, for
  // comparison). Both are unbiased.
  enum class LightSelection { kReach, kPower };
  LightSelection light_selection = LightSelection::kReach;
  bool fluorescence = true;   // false: fluorophores are ignored (for cost/contrast comparisons)
  double noise_target = 0;    // > 0: stop adding passes once the relative noise falls below this
  // > 0: after a path's first diffuse bounce, wet coatings are treated as at least this rough
  // (path regularisation, Kaplanyan & Dachsbacher 2013). Biased but removes the fireflies of LED
  // highlights seen through a diffuse/fluorescent bounce; 0 (default) = exact.
  double regularize_glossy = 0;
  // Optional camera description: camera wavelengths are then sampled half uniformly and half in
  // proportion to the camera's system QE (filters x QE, all channels), so fewer lanes are spent
  // where the camera is blind; the estimate stays unbiased in every band.
  std::string importance_camera;
};

struct SphereShape {
  glm::dvec3 center{0, 0, 0};
  double radius = 1;
  int material = -1;
};

struct DiskShape {
  glm::dvec3 center{0, 0, 0}, normal{0, 0, 1};
  double radius = 1;
  int material = -1;
};

struct Scene {
  std::string file;
  CameraSpec camera;
  IntegratorSpec integrator;
  std::vector<Material> materials;
  std::vector<GridEem> eems;      // fluorophores referenced by materials
  std::vector<Texture> textures;
  std::vector<TriangleMesh> meshes;
  std::vector<SphereShape> spheres;
  std::vector<DiskShape> disks;
  std::vector<LedLight> lights;

  const WavelengthGrid& grid() const { return integrator.grid; }
};

// Command-line overrides (--spp, --seed), applied after the file is read.
struct SceneOverrides {
  std::optional<int> spp;
  std::optional<uint64_t> seed;
  std::optional<int> width, height;
};

Scene load_scene(const std::filesystem::path& file, const SceneOverrides& overrides = {});
// The material at a surface point: a "regions" material resolves to the material its masks give at
// (u, v) or its spheres give at p; any other material is itself.
int resolve_material(const Scene& scene, int material, float u, float v, const glm::dvec3& p);
// How texture coordinates stretch along a surface: the Gram matrix of their gradients (per metre),
// uu = |grad u|^2, uv = grad u . grad v, vv = |grad v|^2. All zero: (u, v) do not change along it.
struct UvMetric {
  double uu = 0, uv = 0, vv = 0;
};
// A lower bound, in metres, on the distance from p to the nearest point of the surface's tangent
// plane (texture coordinates (u, v) at p, stretching as `metric`) where resolve_material's answer can
// change: the distance to the nearest sphere of a "regions" material, and for a texture mask its
// side distance at the nearest texel less 1.5 sqrt 2 texels, over the mask's largest stretch
// (side_distance_texels); infinite for a material without regions.
double region_clearance_m(const Scene& scene, int material, const glm::dvec3& p, float u, float v, const UvMetric& metric);
// The same without texture coordinates: 0 when a texture mask decides.
double region_clearance_m(const Scene& scene, int material, const glm::dvec3& p);
Scene load_scene(const JsonFile& doc, const SceneOverrides& overrides = {});

}  // namespace ofl
