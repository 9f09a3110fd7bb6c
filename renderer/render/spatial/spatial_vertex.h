// Layered tissue with lateral transport ("transport": "spatial"): at a camera-path vertex on such
// a material, light leaves at the vertex x_o but entered elsewhere (docs/layered-tissue.md,
// "Lateral transport"). The stack's BSSRDF is taken as separable: the position-free table's
// directional response (renderer/render/stack_response.h) times a radial profile from
// stack_profiles.h. Per vertex:
// 1. The top interface's specular lobe stays at x_o (closed form, next-event estimation there).
// 2. Two subsurface strategies, each run with a probability that follows what it is expected to add
//    (the larger always; both when the path continues from its entry), its estimates divided by it:
//    - elastic: an entry point x_i at distance r drawn from the elastic exit profile of the lanes'
//      wavelengths (for the viewer's cosine; by reciprocity where light leaving toward the viewer
//      entered), found on the mesh by a probe ray (renderer/render/spatial/surface_probe.h);
//    - fluorescent: a depth slice Z and an emission point x_m under the surface, displaced from x_o
//      by the emission leg (the spread of the emission wavelength from depth Z), then x_i displaced
//      from x_m by the excitation leg (the spread of the LED's light down to Z). The fluorophores at
//      x_m are those of the material found at x_m, so a lesion's fluorescence comes from inside
//      the lesion and is blurred by the emission's own spread.
//    Next-event estimation to an LED from x_i; with MIS against the continuation for reflected light,
//    the deterministic sum over the LED's bins for fluorescence (as everywhere else).
// 3. The continuation is the top lobe's reflection from x_o, or leaves x_i (cosine lobe) carrying
//    the chosen strategy's lanes (fluorescent lanes move to an excitation wavelength drawn from the
//    table).
// Across `regions`: reflected light follows the material where it entered, fluorescence the material
// at the emission point (docs/layered-tissue.md, "Regions and lateral transport").
#pragma once
#include "renderer/render/embree_scene.h"
#include "renderer/render/path_lanes.h"
#include "renderer/render/ray_counts.h"
#include "renderer/render/render_tables.h"
#include "renderer/render/rng.h"
#include "renderer/render/sampling.h"

namespace ofl {

struct SpatialScatter {
  bool ok = false;         // the path continues
  SurfacePoint from;       // where it continues from (x_o or x_i)
  glm::dvec3 wi_world{0, 0, 0};
  double pdf = 0;          // MIS density for an LED hit along wi_world; 0 = count it fully
  bool reflected = false;  // the continuation is the top interface's reflection at x_o
};

class SpatialTransport {
 public:
  SpatialTransport(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables)
      : scene_(scene), embree_(embree), t_(tables) {}

  // xo: the vertex (normals facing the viewer), geom: its Embree geometry (probes look for points of
  // the same mesh), wo: local direction to the viewer in `frame`. Adds the light gathered to the
  // lanes' L/Lf and updates their throughput, wavelength and flags for the continuation.
  SpatialScatter scatter(const SurfacePoint& xo, unsigned geom, const Frame& frame, const glm::dvec3& wo,
                         const MaterialTables& mt, PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;

 private:
  struct Vertex;
  struct Entry;
  // The probabilities of running each subsurface strategy's next-event estimation (beyond the one the
  // path continues from) and of continuing from the fluorescent strategy's entry.
  struct Plan {
    double run_el = 0, run_fl = 0, cont_fl = 0;
  };
  Plan plan(const Vertex& v) const;
  LightSample connect(int light, const SurfacePoint& x, const Frame& f, Rng& rng, RayCounts& counts, RayLog* log) const;
  void top_light(Vertex& v, Rng& rng, RayCounts& counts, RayLog* log) const;
  Entry sample_elastic(Vertex& v, Rng& rng, RayCounts& counts) const;
  Entry sample_fluorescent(Vertex& v, Rng& rng, RayCounts& counts) const;
  void entry_light(Vertex& v, Entry& e, Rng& rng, RayCounts& counts, RayLog* log) const;
  SpatialScatter continue_at_entry(Vertex& v, Entry& e, Rng& rng) const;
  SpatialScatter continue_at_top(Vertex& v, Rng& rng) const;
  bool spatial_material(int material) const;

  const Scene& scene_;
  const EmbreeScene& embree_;
  const RenderTables& t_;
};

}  // namespace ofl
