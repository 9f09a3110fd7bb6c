#include "materials/interfaces/dielectric_interface.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace ofl {

bool refract_smooth(const glm::dvec3& d, double eta, glm::dvec3* out) {
  // Travel direction d crosses the plane z = 0; the tangential part scales by eta.
  double sin2_t = eta * eta * (d.x * d.x + d.y * d.y);
  if (sin2_t >= 1.0) return false;
  double cos_t = std::sqrt(1.0 - sin2_t);
  *out = glm::dvec3(eta * d.x, eta * d.y, d.z < 0 ? -cos_t : cos_t);
  return true;
}

namespace {

glm::dvec3 flip(const glm::dvec3& v, bool f) { return f ? glm::dvec3(v.x, v.y, -v.z) : v; }

// Refraction of wo about m with eta = n_to / n_from; false on total internal reflection.
bool refract_about(const glm::dvec3& wo, const glm::dvec3& m, double eta, glm::dvec3* wt) {
  double ci = glm::dot(wo, m);
  double sin2_t = (1.0 - ci * ci) / (eta * eta);
  if (sin2_t >= 1.0) return false;
  double ct = std::sqrt(1.0 - sin2_t);
  *wt = glm::normalize(-wo / eta + (ci / eta - ct) * m);
  return true;
}

}  // namespace

DielectricInterface::DielectricInterface(double alpha, double n_above, double n_below)
    : alpha_(alpha), n_above_(n_above), n_below_(n_below) {
  ggx_.alpha = std::max(alpha, 1e-4);
  valid_from_above_.fill(1.0);
  valid_from_below_.fill(1.0);
  if (smooth()) return;
  // V(mu) by stratified quadrature over the visible normals, each normal's two branches weighted
  // by their Fresnel probabilities (reflection F, refraction 1 - F).
  const int n = 64;
  for (int side = 0; side < 2; ++side)
    for (int k = 0; k < kTable; ++k) {
      double mu = (k + 0.5) / kTable, s = std::sqrt(1 - mu * mu);
      glm::dvec3 d(s, 0, side == 0 ? -mu : mu);  // from above travelling down, or from below travelling up
      double valid = 0;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          const double u1 = (a + 0.5) / n, u2 = (b + 0.5) / n;
          const Incidence in = incidence(d, u1, u2);
          if (in.ci <= 0) continue;
          const double F = fresnel_dielectric(in.ci, in.eta);
          if (try_once(d, 0.0, u1, u2).weight > 0) valid += F;          // u0 = 0 < F: the reflection
          if (try_once(d, 1.0, u1, u2).weight > 0) valid += 1.0 - F;    // u0 = 1 >= F: the refraction
        }
      (side == 0 ? valid_from_above_ : valid_from_below_)[k] = std::max(valid / (double(n) * n), 1e-6);
    }
}

DielectricInterface::Incidence DielectricInterface::incidence(const glm::dvec3& d, double u1, double u2) const {
  Incidence in;
  in.flipped = d.z > 0;  // travelling up: the incident side is below
  in.wo = -flip(d, in.flipped);
  in.m = smooth() ? glm::dvec3(0, 0, 1) : ggx_.sample_visible_normal(in.wo, u1, u2);
  in.ci = glm::dot(in.wo, in.m);
  in.eta = in.flipped ? n_above_ / n_below_ : n_below_ / n_above_;
  return in;
}

InterfaceEvent DielectricInterface::try_once(const glm::dvec3& d, double u0, double u1, double u2) const {
  const auto [flipped, wo, m, ci, eta] = incidence(d, u1, u2);
  InterfaceEvent e;
  if (ci <= 0) return e;
  glm::dvec3 w;
  if (u0 < fresnel_dielectric(ci, eta)) {
    w = 2.0 * ci * m - wo;
    if (w.z <= 0) return e;
  } else {
    if (!refract_about(wo, m, eta, &w) || w.z >= 0) return e;
    e.transmitted = true;
  }
  e.weight = 1.0;
  e.dir = flip(w, flipped);
  return e;
}

double DielectricInterface::valid_fraction(const glm::dvec3& d) const {
  if (smooth()) return 1.0;
  const auto& t = d.z > 0 ? valid_from_below_ : valid_from_above_;
  double x = std::clamp(std::abs(d.z), 0.0, 1.0) * kTable - 0.5;
  int i = std::clamp(int(std::floor(x)), 0, kTable - 2);
  double f = std::clamp(x - i, 0.0, 1.0);
  return t[i] * (1 - f) + t[i + 1] * f;
}

InterfaceEvent DielectricInterface::transmit(const glm::dvec3& d, double u1, double u2) const {
  const auto [flipped, wo, m, ci, eta] = incidence(d, u1, u2);
  InterfaceEvent e;
  if (ci <= 0) return e;
  glm::dvec3 w;
  if (!refract_about(wo, m, eta, &w) || w.z >= 0) return e;
  e.transmitted = true;
  e.dir = flip(w, flipped);
  double g1_w = smooth() ? 1.0 : 1.0 / (1.0 + ggx_.lambda(w)), g1_o = smooth() ? 1.0 : 1.0 / (1.0 + ggx_.lambda(wo));
  e.weight = (1.0 - fresnel_dielectric(ci, eta)) * g1_w / g1_o / valid_fraction(-e.dir);
  return e;
}

double DielectricInterface::reflection(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (smooth() || wo.z <= 0 || wi.z <= 0) return 0;
  glm::dvec3 h = glm::normalize(wo + wi);
  double F = fresnel_dielectric(glm::dot(wi, h), n_below_ / n_above_);
  double g1 = 1.0 / (1.0 + ggx_.lambda(wo));
  return F * ggx_.D(h) * g1 / (4.0 * wo.z * wi.z * valid_fraction(-wo));
}

}  // namespace ofl
