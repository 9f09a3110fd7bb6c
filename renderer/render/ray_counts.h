// Counts of the rays a render traces, by kind, and an optional log of them (for timing Embree alone
// on the same rays, benchmarks/speed.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace ofl {

struct RayCounts {
  uint64_t camera = 0, extension = 0, shadow = 0;
  uint64_t probe = 0;  // probe rays of the spatial transport (renderer/render/spatial/surface_probe.h)
  uint64_t total() const { return camera + extension + shadow + probe; }
  void operator+=(const RayCounts& o) {
    camera += o.camera;
    extension += o.extension;
    shadow += o.shadow;
    probe += o.probe;
  }
};

// Optional log of traced rays, for timing Embree alone on the same rays. Not thread safe:
// record with one thread (the speed benchmark does).
struct RayLog {
  struct Ray { float o[3], d[3], tmax; bool shadow; };
  std::vector<Ray> rays;
  size_t limit = 0;  // 0 = off
};

// Appends a ray to the log while it is below its limit (no-op without a log).
void record_ray(RayLog* log, const glm::dvec3& o, const glm::dvec3& d, float tmax, bool shadow);

}  // namespace ofl
