// The spectral path tracer (DESIGN.md section 6). A camera sample carries kLanes wavelength lanes
// that share one geometric path. At every surface each lane either reflects or, at a fluorescent
// surface, is re-radiated: it samples an excitation wavelength in proportion to Phi(em, .) and
// continues at that wavelength while keeping its camera wavelength for the film. Direct light from
// the LEDs is next-event estimated with MIS for disk emitters; direct excitation of fluorophores is
// summed over excitation wavelengths deterministically from precomputed tables. Layered tissue
// (materials/layered.h) is entered through a stochastic position-free random walk that does its
// own next-event estimation at every scattering event (renderer/render/layered_vertex.h).
// Transport is in photon units.
#pragma once
#include <cstdint>
#include <vector>

#include "renderer/render/embree_scene.h"
#include "renderer/render/light_choice.h"
#include "renderer/render/render_tables.h"
#include "renderer/render/path_lanes.h"
#include "renderer/render/rng.h"

namespace ofl {

// The stages of a camera sample whose time RayCounts can measure (benchmarks/speed.cpp prints them):
// making the camera ray and choosing wavelengths; Embree intersections of camera and continuation
// rays; the hit point, its normals and material; choosing an LED and a point on it; Embree shadow
// rays; surface shading (light sample, continuation, Russian roulette); a layered-tissue vertex
// (stack tables or walk: everything after its light sample); adding the sample to the film bands.
enum class Stage : int { kCamera, kIntersect, kSurface, kLightChoice, kShadow, kShading, kLayered, kFilm };
constexpr int kStages = 8;
const char* stage_name(int stage);
uint64_t stage_clock();  // CPU time-stamp counter (steady_clock nanoseconds where there is none)

// Rays traced, and with `timing` on, clock ticks per stage: mark(s) gives stage s the ticks since
// the previous mark (or start()). Off by default: a mark is then one untaken branch.
struct RayCounts {
  uint64_t camera = 0, extension = 0, shadow = 0;
  bool timing = false;
  uint64_t last_tick = 0;
  uint64_t ticks[kStages] = {};
  uint64_t total() const { return camera + extension + shadow; }
  void start() {
    if (timing) last_tick = stage_clock();
  }
  void mark(Stage s) {
    if (!timing) return;
    const uint64_t now = stage_clock();
    ticks[int(s)] += now - last_tick;
    last_tick = now;
  }
  void operator+=(const RayCounts& o) {
    camera += o.camera; extension += o.extension; shadow += o.shadow;
    for (int i = 0; i < kStages; ++i) ticks[i] += o.ticks[i];
  }
};

// Optional log of traced rays, for timing Embree alone on the same rays. Not thread safe:
// record with one thread (the speed benchmark does).
struct RayLog {
  struct Ray { float o[3], d[3], tmax; bool shadow; };
  std::vector<Ray> rays;
  size_t limit = 0;  // 0 = off
};

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
  };

  Ray camera_ray(int x, int y, Rng& rng) const;
  void init_lanes(PathLanes& p, Rng& rng) const;
  int sample_wavelength(double u) const;  // RenderTables::wavelength_pdf.sample(u), via wl_guide_
  // `prev` is the surface point the ray left (its light choice weighs the MIS), when prev_pdf > 0.
  void hit_led(const RayHit& hit, const Ray& ray, double prev_pdf, const SurfacePoint& prev, PathLanes& p) const;
  LightSample sample_light(const SurfacePoint& sp, const Frame& frame, Rng& rng, RayCounts& counts, RayLog* log) const;
  Continuation surface_vertex(const SurfacePoint& sp, const Frame& frame, const glm::dvec3& wo, const MaterialTables& mt,
                              bool diffuse_seen, PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;
  Continuation layered_vertex(const SurfacePoint& sp, const Frame& frame, const glm::dvec3& wo, const MaterialTables& mt,
                              PathLanes& p, Rng& rng, RayCounts& counts, RayLog* log) const;
  bool roulette(PathLanes& p, int depth, Rng& rng) const;
  double splat(const PathLanes& p, double* bands, double* fluorescence) const;

  const Scene& scene_;
  const EmbreeScene& embree_;
  const RenderTables& t_;
  LightChoice light_choice_;
  bool deterministic_;
  // Something a continuation ray can hit and see glowing (a disk LED, an emissive material): without
  // one, a path's last continuation ray, traced only to look for emission, is not traced.
  bool hittable_emitters_ = false;
  // wl_guide_[j]: the wavelength bin for u = j / size; sampling starts there (the same bin as a
  // binary search of the CDF, found in a step or two).
  std::vector<int> wl_guide_;
  // Camera frame.
  glm::dvec3 cam_pos_, cam_right_, cam_up_, cam_fwd_;
  double tan_half_h_, tan_half_w_;
};

void record_ray(RayLog* log, const glm::dvec3& o, const glm::dvec3& d, float tmax, bool shadow);

}  // namespace ofl
