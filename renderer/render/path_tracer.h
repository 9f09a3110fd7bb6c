// The spectral path tracer (DESIGN.md section 6). A camera sample carries kLanes wavelength lanes
// that share one geometric path. At every surface each lane either reflects or, at a fluorescent
// surface, is re-radiated: it samples an excitation wavelength in proportion to Phi(em, .) and
// continues at that wavelength while keeping its camera wavelength for the film. Direct light from
// the LEDs is next-event estimated with MIS for disk emitters; direct excitation of fluorophores is
// summed over excitation wavelengths deterministically from precomputed tables. Transport is in
// photon units.
#pragma once
#include <cstdint>
#include <vector>

#include "renderer/render/embree_scene.h"
#include "renderer/render/render_tables.h"
#include "renderer/render/rng.h"

namespace ofl {

constexpr int kLanes = 8;

struct RayCounts {
  uint64_t camera = 0, extension = 0, shadow = 0;
  uint64_t total() const { return camera + extension + shadow; }
  void operator+=(const RayCounts& o) { camera += o.camera; extension += o.extension; shadow += o.shadow; }
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
  Ray camera_ray(int x, int y, Rng& rng) const;

  const Scene& scene_;
  const EmbreeScene& embree_;
  const RenderTables& t_;
  // Camera frame.
  glm::dvec3 cam_pos_, cam_right_, cam_up_, cam_fwd_;
  double tan_half_h_, tan_half_w_;
};

}  // namespace ofl
