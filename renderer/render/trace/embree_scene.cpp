#include "renderer/render/trace/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {
void embree_error(void*, RTCError code, const char* str) {
  std::fprintf(stderr, "embree error %d: %s\n", static_cast<int>(code), str ? str : "");
}
}  // namespace

EmbreeScene::EmbreeScene(const Scene& sc) : src_(sc) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("cannot create an Embree device");
  rtcSetDeviceErrorFunction(device_, embree_error, nullptr);
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  auto attach = [&](RTCGeometry g, GeomInfo gi) {
    rtcCommitGeometry(g);
    unsigned id = rtcAttachGeometry(scene_, g);
    rtcReleaseGeometry(g);
    if (id >= info_.size()) info_.resize(id + 1);
    info_[id] = gi;
  };
  for (size_t i = 0; i < sc.meshes.size(); ++i) {
    const auto& m = sc.meshes[i];
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.positions.size()));
    for (size_t k = 0; k < m.positions.size(); ++k) { v[3 * k] = m.positions[k].x; v[3 * k + 1] = m.positions[k].y; v[3 * k + 2] = m.positions[k].z; }
    auto* ix = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), m.triangle_count()));
    for (size_t k = 0; k < m.indices.size(); ++k) ix[k] = m.indices[k];
    attach(g, {GeomInfo::Kind::kMesh, static_cast<int>(i), m.material_id});
  }
  for (size_t i = 0; i < sc.spheres.size(); ++i) {
    const auto& s = sc.spheres[i];
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
    v[0] = float(s.center.x); v[1] = float(s.center.y); v[2] = float(s.center.z); v[3] = float(s.radius);
    attach(g, {GeomInfo::Kind::kSphere, static_cast<int>(i), s.material});
  }
  auto add_disk = [&](glm::dvec3 c, glm::dvec3 n, double r, GeomInfo gi) {
    RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 1));
    v[0] = float(c.x); v[1] = float(c.y); v[2] = float(c.z); v[3] = float(r);
    auto* nb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 1));
    nb[0] = float(n.x); nb[1] = float(n.y); nb[2] = float(n.z);
    attach(g, gi);
  };
  for (size_t i = 0; i < sc.disks.size(); ++i)
    add_disk(sc.disks[i].center, sc.disks[i].normal, sc.disks[i].radius, {GeomInfo::Kind::kDisk, static_cast<int>(i), sc.disks[i].material});
  for (size_t i = 0; i < sc.lights.size(); ++i)
    if (!sc.lights[i].is_point())
      add_disk(sc.lights[i].position, sc.lights[i].axis, sc.lights[i].radius_m, {GeomInfo::Kind::kLed, static_cast<int>(i), -1});
  rtcCommitScene(scene_);
  set_bounds();
}

// Embree's box of the committed scene (empty: lower above upper, so every ray leaves it), widened
// by a few float steps of its largest coordinate so that a ray leaves_scene rejects could not have
// been reported as a hit by Embree's float arithmetic either.
void EmbreeScene::set_bounds() {
  RTCBounds b;
  rtcGetSceneBounds(scene_, &b);
  const float lo[3] = {b.lower_x, b.lower_y, b.lower_z}, hi[3] = {b.upper_x, b.upper_y, b.upper_z};
  float size = 0;
  for (int i = 0; i < 3; ++i)
    if (lo[i] <= hi[i]) size = std::max({size, std::fabs(lo[i]), std::fabs(hi[i])});
  const float margin = 4 * std::numeric_limits<float>::epsilon() * size;
  for (int i = 0; i < 3; ++i) {
    lo_[i] = lo[i] - margin;
    hi_[i] = hi[i] + margin;
  }
}

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

RayHit EmbreeScene::intersect(const glm::dvec3& o, const glm::dvec3& d, float tmax) const {
  if (leaves_scene(o, d)) return {};
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = float(o.x); rh.ray.org_y = float(o.y); rh.ray.org_z = float(o.z);
  rh.ray.dir_x = float(d.x); rh.ray.dir_y = float(d.y); rh.ray.dir_z = float(d.z);
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = tmax;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &ctx, &rh);
  RayHit h;
  h.geom = rh.hit.geomID;
  if (h.found()) {
    h.t = rh.ray.tfar;
    h.prim = rh.hit.primID;
    h.u = rh.hit.u;
    h.v = rh.hit.v;
    h.ng = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
  }
  return h;
}

bool EmbreeScene::occluded(const glm::dvec3& o, const glm::dvec3& d, float tmax) const {
  if (leaves_scene(o, d)) return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  r.org_x = float(o.x); r.org_y = float(o.y); r.org_z = float(o.z);
  r.dir_x = float(d.x); r.dir_y = float(d.y); r.dir_z = float(d.z);
  r.tnear = 0.0f;
  r.tfar = tmax;
  r.time = 0.0f;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
  rtcOccluded1(scene_, &ctx, &r);
  return r.tfar < 0.0f;
}

void EmbreeScene::occluded_many(const glm::dvec3* o, const glm::dvec3* d, const float* tmax, int n,
                                bool* blocked) const {
  if (n <= 0) return;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  thread_local std::vector<RTCRay> rays;  // per thread: no allocation per call
  rays.resize(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    RTCRay& r = rays[size_t(i)];
    r.org_x = float(o[i].x); r.org_y = float(o[i].y); r.org_z = float(o[i].z);
    r.dir_x = float(d[i].x); r.dir_y = float(d[i].y); r.dir_z = float(d[i].z);
    r.tnear = 0.0f;
    r.tfar = tmax[i];
    r.time = 0.0f;
    r.mask = 0xFFFFFFFFu;
    r.id = unsigned(i);
    r.flags = 0;
  }
  rtcOccluded1M(scene_, &ctx, rays.data(), unsigned(n), sizeof(RTCRay));
  for (int i = 0; i < n; ++i) blocked[i] = rays[size_t(i)].tfar < 0.0f;
}

SurfacePoint EmbreeScene::surface(const RayHit& h, const glm::dvec3& o, const glm::dvec3& d) const {
  SurfacePoint s;
  const GeomInfo& gi = info_[h.geom];
  s.material = gi.material;
  s.p = o + double(h.t) * d;
  switch (gi.kind) {
    case GeomInfo::Kind::kMesh: {
      const auto& m = src_.meshes[gi.index];
      if (m.normals.empty() && m.uvs.empty()) {
        // Flat and without texture coordinates: Embree's geometric normal is all there is to know,
        // and fetching the triangle's indices and vertices here (cache misses on a large mesh) cost
        // about a tenth of the render time of the 198k-triangle benchmark scene.
        glm::dvec3 n(h.ng);
        double len = glm::length(n);
        if (len > 0) {
          s.ng = s.ns = n / len;
          break;
        }
      }
      uint32_t i0 = m.indices[3 * h.prim], i1 = m.indices[3 * h.prim + 1], i2 = m.indices[3 * h.prim + 2];
      glm::dvec3 p0 = m.positions[i0], p1 = m.positions[i1], p2 = m.positions[i2];
      double b1 = h.u, b2 = h.v, b0 = 1.0 - b1 - b2;
      s.p = b0 * p0 + b1 * p1 + b2 * p2;  // more accurate than o + t d
      glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
      double len = glm::length(n);
      s.ng = len > 0 ? n / len : glm::dvec3(glm::normalize(h.ng));
      s.ns = s.ng;
      if (!m.normals.empty()) {
        glm::dvec3 sn = b0 * glm::dvec3(m.normals[i0]) + b1 * glm::dvec3(m.normals[i1]) + b2 * glm::dvec3(m.normals[i2]);
        double sl = glm::length(sn);
        if (sl > 0) s.ns = sn / sl;
        if (glm::dot(s.ns, s.ng) < 0) s.ns = -s.ns;  // keep both on the same side
      }
      if (!m.uvs.empty()) s.uv = float(b0) * m.uvs[i0] + float(b1) * m.uvs[i1] + float(b2) * m.uvs[i2];
      break;
    }
    case GeomInfo::Kind::kSphere: {
      const auto& sp = src_.spheres[gi.index];
      s.ng = glm::normalize(s.p - sp.center);
      s.p = sp.center + sp.radius * s.ng;
      s.ns = s.ng;
      s.uv = {float(0.5 + std::atan2(s.ng.y, s.ng.x) / (2 * kPi)), float(std::acos(std::clamp(s.ng.z, -1.0, 1.0)) / kPi)};
      break;
    }
    case GeomInfo::Kind::kDisk:
    case GeomInfo::Kind::kLed: {
      glm::dvec3 n = gi.kind == GeomInfo::Kind::kDisk ? src_.disks[gi.index].normal : src_.lights[gi.index].axis;
      s.ng = s.ns = n;
      break;
    }
  }
  s.scale = std::max({std::fabs(s.p.x), std::fabs(s.p.y), std::fabs(s.p.z), 1e-2});
  s.material = resolve_material(src_, s.material, s.uv.x, s.uv.y, s.p);  // "regions" materials
  return s;
}

UvGradient EmbreeScene::uv_gradient(const RayHit& h) const {
  UvGradient g;
  const GeomInfo& gi = info_[h.geom];
  if (gi.kind != GeomInfo::Kind::kMesh) return g;
  const auto& m = src_.meshes[gi.index];
  if (m.uvs.empty()) return g;
  const uint32_t i0 = m.indices[3 * h.prim], i1 = m.indices[3 * h.prim + 1], i2 = m.indices[3 * h.prim + 2];
  const glm::dvec3 e1 = glm::dvec3(m.positions[i1]) - glm::dvec3(m.positions[i0]);
  const glm::dvec3 e2 = glm::dvec3(m.positions[i2]) - glm::dvec3(m.positions[i0]);
  const glm::dvec2 a1 = glm::dvec2(m.uvs[i1]) - glm::dvec2(m.uvs[i0]), a2 = glm::dvec2(m.uvs[i2]) - glm::dvec2(m.uvs[i0]);
  // The dual basis of (e1, e2) in their plane: dp = dot(b1, dp) e1 + dot(b2, dp) e2.
  const double g11 = glm::dot(e1, e1), g12 = glm::dot(e1, e2), g22 = glm::dot(e2, e2), det = g11 * g22 - g12 * g12;
  if (!(det > 0)) return g;
  const glm::dvec3 b1 = (g22 * e1 - g12 * e2) / det, b2 = (g11 * e2 - g12 * e1) / det;
  g.u = a1.x * b1 + a2.x * b2;
  g.v = a1.y * b1 + a2.y * b2;
  return g;
}

glm::dvec3 EmbreeScene::offset(const SurfacePoint& s, const glm::dvec3& dir) {
  double eps = 1e-5 * s.scale;
  return s.p + (glm::dot(dir, s.ng) >= 0 ? eps : -eps) * s.ng;
}

}  // namespace ofl
