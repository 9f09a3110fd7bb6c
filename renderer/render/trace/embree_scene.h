// The Scene's geometry in Embree 3: triangle meshes, analytic spheres (SPHERE_POINT), disks and
// LED emitter disks (ORIENTED_DISC_POINT). Every ray the renderer traces goes through here.
#pragma once
#include <embree3/rtcore.h>

#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "renderer/scene/scene.h"

namespace ofl {

struct GeomInfo {
  enum class Kind { kMesh, kSphere, kDisk, kLed };
  Kind kind = Kind::kMesh;
  int index = -1;     // into Scene::meshes / spheres / disks / lights
  int material = -1;  // -1 for LEDs
};

struct RayHit {
  float t = 0;
  unsigned geom = RTC_INVALID_GEOMETRY_ID, prim = 0;
  float u = 0, v = 0;
  glm::vec3 ng{0, 0, 1};  // Embree's geometric normal (not normalised)
  bool found() const { return geom != RTC_INVALID_GEOMETRY_ID; }
};

// Where a ray hit a surface, with everything shading needs.
struct SurfacePoint {
  glm::dvec3 p;
  glm::dvec3 ng;  // unit geometric normal (front side as authored)
  glm::dvec3 ns;  // unit shading normal
  glm::vec2 uv{0, 0};
  int material = -1;
  double scale = 0.1;  // magnitude of p, for ray offsets
  bool flipped = false;  // ng and ns were turned to face the viewer (they face away from the authored side)
};

// How a surface's texture coordinates change along it at a hit: du = dot(u, dp), dv = dot(v, dp)
// for a step dp in the triangle's plane (zero where the surface has no texture coordinates).
struct UvGradient {
  glm::dvec3 u{0, 0, 0}, v{0, 0, 0};
};

class EmbreeScene {
 public:
  explicit EmbreeScene(const Scene& scene);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RayHit intersect(const glm::dvec3& o, const glm::dvec3& d, float tmax = 1e30f) const;
  bool occluded(const glm::dvec3& o, const glm::dvec3& d, float tmax) const;
  // Many shadow rays at once through Embree's stream API (rays from nearby origins toward nearby
  // points are traced as packets): blocked[i] is occluded(o[i], d[i], tmax[i]).
  void occluded_many(const glm::dvec3* o, const glm::dvec3* d, const float* tmax, int n, bool* blocked) const;

  const GeomInfo& info(unsigned geom) const { return info_[geom]; }
  size_t geometries() const { return info_.size(); }
  SurfacePoint surface(const RayHit& h, const glm::dvec3& o, const glm::dvec3& d) const;
  UvGradient uv_gradient(const RayHit& h) const;
  RTCScene handle() const { return scene_; }

  // A point offset off the surface toward `dir`, to start a ray without hitting the surface again.
  static glm::dvec3 offset(const SurfacePoint& s, const glm::dvec3& dir);

  // The ray from o along d, as Embree receives it (in float), starts outside the bounding box of
  // everything in the scene (LED disks included) on some axis and does not move toward it there:
  // it can hit nothing. intersect and occluded answer such rays without Embree; the path tracer
  // ends a path whose continuation ray is one before doing that vertex's remaining work.
  bool leaves_scene(const glm::dvec3& o, const glm::dvec3& d) const {
    const float of[3] = {float(o.x), float(o.y), float(o.z)}, df[3] = {float(d.x), float(d.y), float(d.z)};
    for (int i = 0; i < 3; ++i)
      if ((of[i] > hi_[i] && df[i] >= 0) || (of[i] < lo_[i] && df[i] <= 0)) return true;
    return false;
  }
  // Every continuation ray that leaves s on the side of its geometric normal leaves_scene: the
  // normal lies exactly along an axis and the offset point (offset toward ng) is already beyond the
  // scene's box on that axis (an outward face of the box, e.g. a lone flat patch). Then dot(d, ng) > 0
  // gives d that axis's sign, so leaves_scene(offset(s, d), d) holds for every such d; the path
  // tracer ends the path there without sampling the direction (the same paths, so the same image).
  bool outward_face(const SurfacePoint& s) const {
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      if (s.ng[i] == 0 || s.ng[j] != 0 || s.ng[k] != 0) continue;
      const float o = float(offset(s, s.ng)[i]);
      return s.ng[i] > 0 ? o > hi_[i] : o < lo_[i];
    }
    return false;
  }

 private:
  const Scene& src_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<GeomInfo> info_;
  void set_bounds();
  // The scene's bounding box, widened by a margin above float rounding (leaves_scene).
  float lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
};

}  // namespace ofl
