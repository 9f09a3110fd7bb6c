// Probe rays for the spatial transport (see surface_probe.h).
#include "renderer/render/spatial/surface_probe.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace ofl {

namespace {

constexpr double kMmPerMetre = 1000.0;

const glm::dvec3& axis_of(const Frame& f, int a) { return a == 0 ? f.z : a == 1 ? f.x : f.y; }

}  // namespace

int probe_segment(const EmbreeScene& e, unsigned geom, const glm::dvec3& a, const glm::dvec3& b, SurfacePoint* out) {
  const glm::dvec3 span = b - a;
  const double length = glm::length(span);
  if (!(length > 0)) return 0;
  const glm::dvec3 d = span / length;
  double t0 = 0;
  int found = 0;
  for (int guard = 0; guard < 4 * kMaxProbeHits && found < kMaxProbeHits; ++guard) {
    const glm::dvec3 o = a + t0 * d;
    const RayHit h = e.intersect(o, d, float(length - t0));
    if (!h.found()) break;
    const double t = t0 + h.t;
    if (h.geom == geom) out[found++] = e.surface(h, o, d);
    // Step past the crossing by a little more than float precision at this scale.
    const double eps = 1e-6 * std::max({std::abs(o.x), std::abs(o.y), std::abs(o.z), 1e-2});
    t0 = t + eps;
    if (t0 >= length) break;
  }
  return found;
}

ProbeResult probe_around(const EmbreeScene& e, unsigned geom, const glm::dvec3& centre, const Frame& frame, double r_mm,
                         double phi, int axis, double search_mm, double u) {
  ProbeResult res;
  res.axis = axis;
  if (!(r_mm < search_mm)) return res;
  const glm::dvec3& n = axis_of(frame, axis);
  const glm::dvec3& s = axis_of(frame, (axis + 1) % 3);
  const glm::dvec3& t = axis_of(frame, (axis + 2) % 3);
  const double h = std::sqrt(search_mm * search_mm - r_mm * r_mm) / kMmPerMetre;
  const glm::dvec3 mid = centre + (r_mm / kMmPerMetre) * (std::cos(phi) * s + std::sin(phi) * t);
  SurfacePoint hits[kMaxProbeHits];
  res.hits = probe_segment(e, geom, mid + h * n, mid - h * n, hits);
  if (res.hits == 0) return res;
  const int pick = std::min(int(u * res.hits), res.hits - 1);
  res.sp = hits[pick];
  res.found = true;
  return res;
}

double probe_density(const glm::dvec3& centre, const Frame& frame, const SurfacePoint& x, int hits,
                     const std::function<double(double)>& planar_density) {
  if (hits <= 0) return 0;
  const glm::dvec3 d = (x.p - centre) * kMmPerMetre;
  double pdf = 0;
  for (int a = 0; a < 3; ++a) {
    const glm::dvec3& ax = axis_of(frame, a);
    const double along = glm::dot(d, ax);
    const double r = std::sqrt(std::max(0.0, glm::dot(d, d) - along * along));
    pdf += kProbeAxisProbability[a] * planar_density(r) * std::abs(glm::dot(x.ng, ax));
  }
  return pdf / hits;
}

}  // namespace ofl
