// The spectral path tracer (docs/transport.md). A camera sample carries kLanes wavelength lanes
// that share one geometric path. At every surface each lane either reflects or, at a fluorescent
// surface, is re-radiated: it samples an excitation wavelength in proportion to Phi(em, .) and
// continues at that wavelength while keeping its camera wavelength for the film. Direct light from
// the LEDs is next-event estimated with MIS for disk emitters; direct excitation of fluorophores is
// summed over excitation wavelengths deterministically from precomputed tables. Layered tissue
// (materials/description/layered.h) is entered through a stochastic position-free random walk that does its
// own next-event estimation at every scattering event (PathTracer::layered_vertex in
// path_tracer.cpp; docs/layered-tissue.md).
// Transport is in photon units.
#pragma once
#include <cstdint>
#include <vector>

#include "renderer/render/trace/embree_scene.h"
#include "renderer/render/trace/light_choice.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/trace/path_lanes.h"
#include "renderer/render/trace/ray_counts.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/integrator/spatial_vertex.h"

namespace ofl {


class PathTracer {
 public:
  PathTracer(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables);

  // Traces one camera sample of pixel (x, y) and adds its band radiance (W sr^-1 m^-2 nm^-1,
  // already divided by the wavelength pdf and the lane count) to `bands`, and the part of it that
  // is fluorescence (light re-radiated at least once on its way) to `fluorescence` when given.
  // Returns the sum of what it added over all bands (for noise estimates).
  double sample_pixel(int x, int y, Rng& rng, double* bands, RayCounts& counts, RayLog* log = nullptr,
                      double* fluorescence = nullptr) const;

 private:
  struct Ray { glm::dvec3 o, d; };
  // What a vertex hands to the next: the continuation ray's direction and its solid-angle pdf for
  // MIS when it hits an LED (0 = count the hit fully), or no continuation.
  struct Continuation {
    bool ok = false;
    glm::dvec3 wi_world{0, 0, 0};
    double pdf = 0;
    bool diffuse = false;  // left through a diffuse lobe (glossy regularisation)
    bool moved = false;    // leaves from `from` (lateral transport moved the path), not the vertex
    SurfacePoint from;
    bool light_by_power = false;  // the vertex's next-event estimation chose its LED by power alone
  };

  Ray camera_ray(int x, int y, Rng& rng) const;
  void init_lanes(PathLanes& p, Rng& rng) const;
  // `prev` is the surface point the ray left, when prev_pdf > 0: the MIS weight uses the probability
  // its next-event estimation gave this LED (by what the LED can give it, or by power alone).
  void hit_led(const RayHit& hit, const Ray& ray, double prev_pdf, const SurfacePoint& prev, bool prev_by_power,
               PathLanes& p) const;
  LightSample sample_light(const SurfacePoint& sp, const Frame& frame, Rng& rng, RayCounts& counts, RayLog* log) const;
  Continuation surface_vertex(const SurfacePoint& sp, const Frame& frame, const glm::dvec3& wo, const MaterialTables& mt,
                              bool diffuse_seen, PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;
  Continuation layered_vertex(const SurfacePoint& sp, const RayHit& hit, const Frame& frame, const glm::dvec3& wo, const MaterialTables& mt,
                              PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;
  Continuation spatial_vertex(const SurfacePoint& sp, unsigned geom, const Frame& frame, const glm::dvec3& wo,
                              const MaterialTables& mt, PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;
  bool roulette(PathLanes& p, int depth, Rng& rng) const;
  double splat(const PathLanes& p, double* bands, double* fluorescence) const;

  const Scene& scene_;
  const EmbreeScene& embree_;
  const RenderTables& t_;
  GuidedSampler wavelengths_;  // RenderTables::wavelength_pdf without its binary search
  // RenderTables::band_weights in one array (splat reads them once per lane): grid index i's weights
  // are film_bw_[film_first_[i] .. film_first_[i + 1]).
  std::vector<RenderTables::BandWeight> film_bw_;
  std::vector<int> film_first_;
  LightChoice light_choice_;
  SpatialTransport spatial_;
  bool deterministic_;
  // Something a continuation ray can hit and see glowing (a disk LED, an emissive material): without
  // one, a path's last continuation ray, traced only to look for emission, is not traced.
  bool hittable_emitters_ = false;
  // Camera frame.
  glm::dvec3 cam_pos_, cam_right_, cam_up_, cam_fwd_;
  double tan_half_h_, tan_half_w_;
};


}  // namespace ofl
