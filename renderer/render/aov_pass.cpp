#include "renderer/render/aov_pass.h"

#include <tbb/parallel_for.h>

#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/core/progress.h"
#include "renderer/render/sampling.h"

namespace ofl {

double led_irradiance(const Scene& scene, const EmbreeScene& embree, const SurfacePoint& sp) {
  double e = 0;
  for (const LedLight& l : scene.lights) {
    int n = l.is_point() ? 1 : 3;
    double sum = 0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        glm::dvec3 p = l.position;
        if (!l.is_point()) {
          glm::dvec2 d = sample_concentric_disk((a + 0.5) / n, (b + 0.5) / n) * l.radius_m;
          p += d.x * l.tangent + d.y * l.bitangent;
        }
        glm::dvec3 to = p - sp.p;
        double d2 = glm::dot(to, to), d = std::sqrt(d2);
        glm::dvec3 w = to / d;
        double cos_s = glm::dot(w, sp.ns), cos_l = -glm::dot(w, l.axis);
        if (cos_s <= 0 || cos_l <= 0 || glm::dot(w, sp.ng) <= 0) continue;
        glm::dvec3 o = EmbreeScene::offset(sp, w);
        if (embree.occluded(o, w, float(glm::length(p - o) * (1 - 1e-4)))) continue;
        sum += l.intensity_W_sr * l.profile.eval(cos_l) * cos_s / d2;
      }
    e += sum / (n * n);
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
  tbb::parallel_for(0, H, [&](int y) {
    if (interrupt_requested()) return;
    for (int x = 0; x < W; ++x) {
      size_t i = size_t(y) * W + x;
      glm::dvec3 d = glm::normalize(f + (2.0 * (x + 0.5) / W - 1.0) * tw * r + (1.0 - 2.0 * (y + 0.5) / H) * th * u);
      RayHit h = embree.intersect(c.position, d);
      if (!h.found()) { out["aov.material"][i] = -1; continue; }
      const GeomInfo& gi = embree.info(h.geom);
      out["aov.depth"][i] = h.t;
      if (gi.kind == GeomInfo::Kind::kLed) { out["aov.material"][i] = -2; continue; }
      SurfacePoint sp = embree.surface(h, c.position, d);
      if (glm::dot(sp.ng, -d) < 0) { sp.ng = -sp.ng; sp.ns = -sp.ns; }
      out["aov.material"][i] = float(sp.material);
      out["aov.u"][i] = sp.uv.x;
      out["aov.v"][i] = sp.uv.y;
      out["aov.cos_view"][i] = float(glm::dot(sp.ns, -d));
      out["aov.irradiance"][i] = float(led_irradiance(scene, embree, sp));
    }
  });
  if (interrupt_requested()) out.clear();
  return out;
}

}  // namespace ofl
