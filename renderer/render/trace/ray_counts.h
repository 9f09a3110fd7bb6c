// Counts of the rays a render traces, by kind, optional clock ticks per stage of a camera sample,
// and an optional log of the rays (for timing Embree alone on the same rays, benchmarks/speed.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace ofl {

// The stages of a camera sample whose time RayCounts can measure (benchmarks/speed.cpp prints them):
// making the camera ray and choosing wavelengths; Embree intersections of camera and continuation
// rays; the hit point, its normals and material; choosing an LED and a point on it; Embree shadow
// rays; surface shading (light sample, continuation, Russian roulette); a layered-tissue vertex
// (stack tables, walk or spatial transport: everything after its light sample); adding the sample
// to the film bands.
enum class Stage : int { kCamera, kIntersect, kSurface, kLightChoice, kShadow, kShading, kLayered, kFilm };
constexpr int kStages = 8;
const char* stage_name(int stage);
uint64_t stage_clock();  // CPU time-stamp counter (steady_clock nanoseconds where there is none)

// Rays traced, and with `timing` on, clock ticks per stage: mark(s) gives stage s the ticks since
// the previous mark (or start()). Off by default: a mark is then one untaken branch.
struct RayCounts {
  uint64_t camera = 0, extension = 0, shadow = 0;
  uint64_t probe = 0;  // probe rays of the spatial transport (renderer/render/spatial/surface_probe.h)
  bool timing = false;
  uint64_t last_tick = 0;
  uint64_t ticks[kStages] = {};
  uint64_t total() const { return camera + extension + shadow + probe; }
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
    camera += o.camera;
    extension += o.extension;
    shadow += o.shadow;
    probe += o.probe;
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

// Appends a ray to the log while it is below its limit (no-op without a log).
void record_ray(RayLog* log, const glm::dvec3& o, const glm::dvec3& d, float tmax, bool shadow);

}  // namespace ofl
