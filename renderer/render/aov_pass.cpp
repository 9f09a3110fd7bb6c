#include "renderer/render/aov_pass.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>

#include "renderer/core/process/progress.h"
#include "renderer/render/trace/sampling.h"

namespace ofl {

std::vector<std::vector<glm::dvec3>> led_sample_points(const Scene& scene) {
  std::vector<std::vector<glm::dvec3>> out;
  for (const LedLight& l : scene.lights) {
    out.emplace_back();
    const int n = l.is_point() ? 1 : 3;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        glm::dvec3 p = l.position;
        if (!l.is_point()) {
          glm::dvec2 d = sample_concentric_disk((a + 0.5) / n, (b + 0.5) / n) * l.radius_m;
          p += d.x * l.tangent + d.y * l.bitangent;
        }
        out.back().push_back(p);
      }
  }
  return out;
}

double led_irradiance(const Scene& scene, const EmbreeScene& embree, const SurfacePoint& sp,
                      const std::vector<std::vector<glm::dvec3>>& points) {
  // Every shadow ray of the point is traced in one stream (they share an origin and head for a few
  // small discs, so Embree traces them as packets); the sums are taken in the same order as the
  // rays were made, so the value does not depend on how they were traced. Per-thread buffers: no
  // allocation per pixel.
  thread_local std::vector<glm::dvec3> o, w;
  thread_local std::vector<float> tmax;
  thread_local std::vector<double> value;
  thread_local std::vector<size_t> light;
  thread_local std::unique_ptr<bool[]> blocked;
  thread_local size_t blocked_size = 0;
  o.clear(), w.clear(), tmax.clear(), value.clear(), light.clear();
  for (size_t li = 0; li < scene.lights.size(); ++li) {
    const LedLight& l = scene.lights[li];
    for (const glm::dvec3& p : points[li]) {
      glm::dvec3 to = p - sp.p;
      double d2 = glm::dot(to, to), d = std::sqrt(d2);
      glm::dvec3 dir = to / d;
      double cos_s = glm::dot(dir, sp.ns), cos_l = -glm::dot(dir, l.axis);
      if (cos_s <= 0 || cos_l <= 0 || glm::dot(dir, sp.ng) <= 0) continue;
      glm::dvec3 org = EmbreeScene::offset(sp, dir);
      o.push_back(org);
      w.push_back(dir);
      tmax.push_back(float(glm::length(p - org) * (1 - 1e-4)));
      value.push_back(l.intensity_W_sr * l.profile.eval(cos_l) * cos_s / d2);
      light.push_back(li);
    }
  }
  if (blocked_size < o.size() + 1) blocked.reset(new bool[blocked_size = o.size() + 1]);
  embree.occluded_many(o.data(), w.data(), tmax.data(), int(o.size()), blocked.get());
  double e = 0;
  size_t i = 0;
  for (size_t li = 0; li < scene.lights.size(); ++li) {
    double sum = 0;
    for (; i < o.size() && light[i] == li; ++i)
      if (!blocked[i]) sum += value[i];
    e += sum / double(points[li].size());
  }
  return e;
}

ViewProbe probe_view(const Scene& scene, const EmbreeScene& embree, int n) {
  const CameraSpec& c = scene.camera;
  glm::dvec3 f = glm::normalize(c.look_at - c.position);
  glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  glm::dvec3 u = glm::cross(r, f);
  double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0), tw = th * double(c.width) / c.height;
  ViewProbe p;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      glm::dvec3 d = glm::normalize(f + (2.0 * (x + 0.5) / n - 1.0) * tw * r + (1.0 - 2.0 * (y + 0.5) / n) * th * u);
      ++p.rays;
      RayHit h = embree.intersect(c.position, d);
      if (!h.found()) continue;
      ++p.hits;
      if (embree.info(h.geom).kind == GeomInfo::Kind::kLed) continue;
      if (glm::dot(embree.surface(h, c.position, d).ng, d) > 0) ++p.back_hits;
    }
  return p;
}

std::map<std::string, std::vector<float>> compute_aovs(const Scene& scene, const EmbreeScene& embree) {
  const CameraSpec& c = scene.camera;
  const int W = c.width, H = c.height;
  std::map<std::string, std::vector<float>> out;
  for (const char* n : {"aov.material", "aov.u", "aov.v", "aov.depth", "aov.cos_view", "aov.irradiance"})
    out[n].assign(size_t(W) * H, 0.0f);
  glm::dvec3 f = glm::normalize(c.look_at - c.position);
  glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  glm::dvec3 u = glm::cross(r, f);
  double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0), tw = th * double(W) / H;
  float *material = out["aov.material"].data(), *u_plane = out["aov.u"].data(), *v_plane = out["aov.v"].data(),
        *depth = out["aov.depth"].data(), *cos_view = out["aov.cos_view"].data(),
        *irradiance = out["aov.irradiance"].data();
  const auto led_points = led_sample_points(scene);
  tbb::parallel_for(0, H, [&](int y) {
    if (interrupt_requested()) return;
    for (int x = 0; x < W; ++x) {
      size_t i = size_t(y) * W + x;
      glm::dvec3 d = glm::normalize(f + (2.0 * (x + 0.5) / W - 1.0) * tw * r + (1.0 - 2.0 * (y + 0.5) / H) * th * u);
      RayHit h = embree.intersect(c.position, d);
      if (!h.found()) { material[i] = -1; continue; }
      const GeomInfo& gi = embree.info(h.geom);
      depth[i] = h.t;
      if (gi.kind == GeomInfo::Kind::kLed) { material[i] = -2; continue; }
      SurfacePoint sp = embree.surface(h, c.position, d);
      if (glm::dot(sp.ng, -d) < 0) { sp.ng = -sp.ng; sp.ns = -sp.ns; }
      material[i] = float(sp.material);
      u_plane[i] = sp.uv.x;
      v_plane[i] = sp.uv.y;
      cos_view[i] = float(glm::dot(sp.ns, -d));
      irradiance[i] = float(led_irradiance(scene, embree, sp, led_points));
    }
  });
  if (interrupt_requested()) out.clear();
  return out;
}

}  // namespace ofl
