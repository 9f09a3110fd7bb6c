#include "renderer/render/integrator/led_connection.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace ofl {

LightSample connect_to_led(const Scene& scene, const EmbreeScene& embree, const RenderTables& t, int li, double pmf,
                           const SurfacePoint& x, const Frame& f, Rng& rng, RayCounts& counts, RayLog* log) {
  LightSample s;
  const LedLight& led = scene.lights[li];
  glm::dvec3 lp = led.position;
  if (!led.is_point()) {
    const glm::dvec2 d = sample_concentric_disk(rng.next_double(), rng.next_double()) * led.radius_m;
    lp += d.x * led.tangent + d.y * led.bitangent;
  }
  const glm::dvec3 to = lp - x.p;
  const double dist2 = glm::dot(to, to), dist = std::sqrt(dist2);
  const glm::dvec3 wi_w = to / dist;
  const double cos_l = -glm::dot(wi_w, led.axis);
  const glm::dvec3 wi = f.to_local(wi_w);
  if (!(cos_l > 0 && wi.z > 0 && glm::dot(wi_w, x.ng) > 0)) {
    counts.mark(Stage::kLightChoice);
    return s;
  }
  const glm::dvec3 o = EmbreeScene::offset(x, wi_w);
  const float tmax = float(glm::length(lp - o) * (1.0 - 1e-4));
  counts.shadow++;
  record_ray(log, o, wi_w, tmax, true);
  counts.mark(Stage::kLightChoice);
  const bool blocked = embree.occluded(o, wi_w, tmax);
  counts.mark(Stage::kShadow);
  if (blocked) return s;
  s.valid = true;
  s.light = li;
  s.group = t.light_group[li];
  s.wi = wi;
  s.g = led.profile.eval(cos_l) * wi.z / dist2 / pmf * t.light_scale[li];
  s.pdf_solid = led.is_point() ? 0.0 : pmf * dist2 / (led.area() * cos_l);
  return s;
}

}  // namespace ofl
