#include "materials/interfaces/coated.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include <glm/geometric.hpp>

#include "renderer/spectral/spectra/units.h"

namespace ofl {

double fresnel_dielectric(double cos_i, double eta) {
  cos_i = std::clamp(cos_i, 0.0, 1.0);
  double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  double cos_t = std::sqrt(1.0 - sin2_t);
  double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

double GgxCoating::D(const glm::dvec3& h) const {
  if (h.z <= 0) return 0;
  double a2 = alpha * alpha;
  double c2 = h.z * h.z;
  double d = c2 * (a2 - 1.0) + 1.0;
  return a2 / (kPi * d * d);
}

double GgxCoating::lambda(const glm::dvec3& w) const {
  double c2 = w.z * w.z;
  if (c2 >= 1.0) return 0.0;
  double t2 = (1.0 - c2) / c2;
  return 0.5 * (std::sqrt(1.0 + alpha * alpha * t2) - 1.0);
}

double GgxCoating::G2(const glm::dvec3& wo, const glm::dvec3& wi) const { return 1.0 / (1.0 + lambda(wo) + lambda(wi)); }

double GgxCoating::eval(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  glm::dvec3 h = glm::normalize(wo + wi);
  double F = fresnel_dielectric(glm::dot(wi, h), ior);
  return D(h) * G2(wo, wi) * F / (4.0 * wo.z * wi.z);
}

glm::dvec3 GgxCoating::sample_visible_normal(const glm::dvec3& wo, double u1, double u2) const {
  // Visible-normal sampling (Heitz 2018): stretch, sample the projected hemisphere, unstretch.
  glm::dvec3 v = glm::normalize(glm::dvec3(alpha * wo.x, alpha * wo.y, wo.z));
  glm::dvec3 t1 = v.z < 0.9999 ? glm::normalize(glm::cross(glm::dvec3(0, 0, 1), v)) : glm::dvec3(1, 0, 0);
  glm::dvec3 t2 = glm::cross(v, t1);
  double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
  double p1 = r * std::cos(phi), p2 = r * std::sin(phi);
  double s = 0.5 * (1.0 + v.z);
  p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
  glm::dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
  return glm::normalize(glm::dvec3(alpha * nh.x, alpha * nh.y, std::max(1e-9, nh.z)));
}

glm::dvec3 GgxCoating::sample(const glm::dvec3& wo, double u1, double u2) const {
  glm::dvec3 h = sample_visible_normal(wo, u1, u2);
  return 2.0 * glm::dot(wo, h) * h - wo;
}

double GgxCoating::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const {
  if (wo.z <= 0 || wi.z <= 0) return 0;
  glm::dvec3 h = glm::normalize(wo + wi);
  // Visible normal density D_v(h) = G1(wo) max(0, wo.h) D(h) / wo.z, times the reflection Jacobian.
  double g1 = 1.0 / (1.0 + lambda(wo));
  double dv = g1 * std::max(0.0, glm::dot(wo, h)) * D(h) / wo.z;
  return dv / (4.0 * glm::dot(wo, h));
}

double GgxCoating::specular_albedo(double mu) const {
  double x = std::clamp(mu, 0.0, 1.0) * kTable - 0.5;
  int i = std::clamp(static_cast<int>(std::floor(x)), 0, kTable - 2);
  double t = std::clamp(x - i, 0.0, 1.0);
  return albedo[i] * (1 - t) + albedo[i + 1] * t;
}

double GgxCoating::diffuse_kernel(double mu_i, double mu_o) const {
  return (1.0 - specular_albedo(mu_i)) * (1.0 - specular_albedo(mu_o)) / (kPi * (1.0 - albedo_avg));
}

void GgxCoating::prepare(double ior_, double alpha_) {
  // The tables depend only on (ior, alpha) and take ~0.1 s to integrate; scenes (and sweeps) reuse
  // a few pairs many times, so keep every pair computed in this process.
  static std::mutex mu;
  static std::map<std::pair<double, double>, GgxCoating> cache;
  {
    std::lock_guard lock(mu);
    auto it = cache.find({ior_, alpha_});
    if (it != cache.end()) {
      *this = it->second;
      return;
    }
  }
  ior = ior_;
  alpha = std::max(alpha_, 1e-3);
  // E_s(mu) = integral f_s cos dwi, by stratified importance sampling of the lobe (deterministic).
  const int n = 48;  // 48 x 48 stratified samples per angle: E_s to ~1e-3
  for (int k = 0; k < kTable; ++k) {
    double mu = (k + 0.5) / kTable;
    glm::dvec3 wo(std::sqrt(1 - mu * mu), 0, mu);
    double sum = 0;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        glm::dvec3 wi = sample(wo, (a + 0.5) / n, (b + 0.5) / n);
        if (wi.z <= 0) continue;
        double p = pdf(wo, wi);
        if (p > 0) sum += eval(wo, wi) * wi.z / p;
      }
    albedo[k] = std::min(sum / (n * n), 0.999);
  }
  double avg = 0;
  for (int k = 0; k < kTable; ++k) avg += 2.0 * albedo[k] * (k + 0.5) / kTable / kTable;
  albedo_avg = avg;
  // Internal hemispherical reflectance: 1 - (1 - F_ext_avg) / n^2 (light leaving the layer passes
  // the interface with the external transmittance, compressed into the escape cone).
  double fext = 0;
  const int m = 2000;
  for (int k = 0; k < m; ++k) {
    double mu = (k + 0.5) / m;
    fext += 2.0 * fresnel_dielectric(mu, ior) * mu / m;
  }
  internal_reflectance = 1.0 - (1.0 - fext) / (ior * ior);
  std::lock_guard lock(mu);
  cache.emplace(std::make_pair(ior_, alpha_), *this);
}

}  // namespace ofl
