// Layered tissue at a path vertex: one stochastic evaluation and sample of the stack's BSDF
// (materials/description/layered.h; the walk is renderer/render/stack/stack_walk.h; docs/layered-tissue.md).
//
// With transport "walk" the stack's BSDF is evaluated and sampled by one position-free random walk
// per vertex, as pbrt-v4's LayeredBxDF does, extended to several layers, wavelength lanes and
// volume fluorescence (with transport "table", layered_table_scatter reads a table the same walk
// filled at scene load):
// 1. The caller's next-event sample (an LED point, already unoccluded) gives the light direction.
// 2. The top interface's specular reflection toward it is evaluated in closed form (GGX).
// 3. The top interface reflects or refracts the camera path (Fresnel, one sampled microfacet when
//    rough). A refracted path starts the walk; at every collision (and at an opaque base) the walk
//    connects to the light through the layers above: the refracted light direction is fixed for the
//    walk (sampled once through a rough top, by Snell through every smooth internal interface), so
//    the connection costs only the lanes' transmittances. A lane that scatters there adds
//    mus * HG * T * (Fresnel transmittances) / mu with MIS; a lane that would be re-radiated adds
//    the light absorbed at that point by each fluorophore, summed over the light's emitting bins
//    (deterministic direct excitation, no MIS, as at surfaces).
// 4. The continuation is the top reflection, or the walk's exit.
// With transport "volume" the same walk keeps its lateral position in the vertex's tangent plane and
// runs in the material under it (LateralMaterials): where a flight passes from one `regions`
// material into another the walk stops at the crossing and goes on in the other's stack, at the same
// depth and in the same direction (no refraction at the side walls between regions). Next-event
// estimation at a collision goes up through the layers of the material under the collision, with
// the vertex's light sample (the light taken as the same over the walk's spread); fluorescence
// excited by scattered light walks sideways too (its sub-walks are volume walks from the
// collision). The walk's exit continues the path from the vertex. docs/layered-tissue.md,
// "The volume walk".
// MIS between next-event estimation and the walk's exits uses one fixed function of the directions
// (the top lobe's pdf mixed with a cosine lobe) on both sides, so the weights sum to one on every
// path that both strategies can make; a path that reflected off an interface after its last
// scattering event can only be made by the walk and counts fully.
#pragma once
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "renderer/render/trace/path_lanes.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/stack/stack_walk.h"
#include "renderer/image/texture.h"

namespace ofl {

// The material under a point of the volume walk (transport "volume").
class LateralMaterials {
 public:
  virtual ~LateralMaterials() = default;
  // The render tables' material index under the point of the vertex's tangent plane at offset
  // `pos` (mm along the local frame's x and y axes).
  virtual int material_at(const glm::dvec2& pos) const = 0;
  // A lower bound, in mm, on the distance from `pos` to the nearest point where material_at can
  // change (0: none known, every step of a flight is read).
  virtual double clearance(const glm::dvec2& /*pos*/) const { return 0.0; }
};

// What the volume walk needs beyond the vertex's own material.
struct VolumeWalkContext {
  const std::vector<MaterialTables>* materials = nullptr;  // the render tables' materials
  int material = -1;                                       // the vertex's (index into *materials)
  const LateralMaterials* under = nullptr;                 // null: one material everywhere
  const std::vector<Texture>* textures = nullptr;          // for the fluorophores' texture factors
  glm::vec2 uv{0, 0};                                      // the vertex's texture coordinates
};

struct LayeredScatter {
  bool ok = false;         // the path continues
  glm::dvec3 wi{0, 0, 0};  // local continuation direction (z > 0)
  double pdf = 0;          // MIS density for an LED hit along wi; 0 = count it fully
  bool reflected = false;  // the continuation is the top interface's reflection
  WalkResult walk;         // how the walk ended
};

// Adds the light sample's contribution (when valid) to the lanes' L/Lf and replaces the lanes'
// throughput, wavelength and flags by the continuation's. wo is the local direction to the viewer.
// With `volume`, the walk is the volume walk above.
LayeredScatter layered_scatter(const MaterialTables& mt, const StackPointFactors& fac, const glm::dvec3& wo,
                               const LightSample& ls, const std::vector<std::vector<float>>& light_shapes, int n,
                               PathLanes& p, Rng& rng, const VolumeWalkContext* volume = nullptr);

// The same with the stack's tabulated response (mt.stack.response, renderer/render/stack/stack_response.h)
// instead of a walk: the top's specular lobe in closed form as above, the rest interpolated in the
// table; next-event estimation with MIS for reflected light and the deterministic sum over the
// LED's bins for fluorescence, as surface materials do; the continuation from the mixture of the
// top lobe and a cosine lobe (smooth tops: the Fresnel mirror or the cosine lobe).
LayeredScatter layered_table_scatter(const MaterialTables& mt, const glm::dvec3& wo, const LightSample& ls,
                                     const std::vector<std::vector<float>>& light_shapes, PathLanes& p, Rng& rng);

// The texture factors of the stack's fluorophores at a surface point.
StackPointFactors stack_point_factors(const StackTables& st, const std::vector<Texture>& textures, const glm::vec2& uv);

}  // namespace ofl
