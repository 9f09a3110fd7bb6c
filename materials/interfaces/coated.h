// Wet tissue: a dielectric coating (mucus/saliva, n ~ 1.33) with GGX microfacet roughness over a
// Lambertian (possibly fluorescent) base. The specular lobe is a Cook-Torrance GGX reflection with
// exact dielectric Fresnel and the height-correlated Smith masking term. Light that is not
// reflected by the coating reaches the base; its share is 1 - E_s(theta), with E_s the directional
// albedo of the specular lobe (tabulated at set-up), so that specular + diffuse never exceeds 1
// for any incident direction:
//   f_diffuse(i, o) = (1 - E_s(i)) (1 - E_s(o)) / (pi (1 - E_avg)) * A_eff
// where E_avg = 2 int E_s(mu) mu dmu, and A_eff = (1 - F_int) sum_n F_int^n A^{n+1} accounts for
// light bouncing between the base and the inside of the coating (F_int = hemispherical internal
// reflectance of the interface, large because of total internal reflection). The renderer samples
// n ~ Geometric(F_int) so A_eff is applied one albedo-matrix step at a time (fluorescence included).
// The kernel is reciprocal and the albedo E_s(i) + (1 - E_s(i)) rho (1-F_int)/(1 - rho F_int) <= 1.
#pragma once
#include <array>

#include <glm/vec3.hpp>

namespace ofl {

// Exact Fresnel reflectance of unpolarised light at a dielectric interface; cos_i measured on the
// side of the incident light, eta = n_transmitted / n_incident. Total internal reflection gives 1.
double fresnel_dielectric(double cos_i, double eta);

// Directions in the local frame: z is the shading normal, both directions point away from the
// surface (z > 0 on the reflecting side).
struct GgxCoating {
  double ior = 1.33;
  double alpha = 0.15;
  static constexpr int kTable = 64;
  std::array<double, kTable> albedo{};  // E_s at mu = (k + 0.5) / kTable
  double albedo_avg = 0;                // E_avg
  double internal_reflectance = 0;      // F_int: diffuse light reflected back by the interface from inside

  // Precomputes the tables (numerical integration); call once per (ior, alpha).
  void prepare(double ior, double alpha);

  double D(const glm::dvec3& h) const;
  double lambda(const glm::dvec3& w) const;
  double G2(const glm::dvec3& wo, const glm::dvec3& wi) const;  // height-correlated Smith
  // Specular BRDF value (no cosine), 0 when either direction is below the surface.
  double eval(const glm::dvec3& wo, const glm::dvec3& wi) const;
  // A microfacet normal h from the distribution of normals visible from wo (wo.z > 0, Heitz 2018):
  // density G1(wo) max(0, wo.h) D(h) / wo.z.
  glm::dvec3 sample_visible_normal(const glm::dvec3& wo, double u1, double u2) const;
  // Samples wi from the distribution of visible normals (Heitz 2018) reflected about h.
  glm::dvec3 sample(const glm::dvec3& wo, double u1, double u2) const;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const;
  // Directional albedo E_s(mu) by table lookup, and the diffuse kernel without A_eff.
  double specular_albedo(double mu) const;
  double diffuse_kernel(double mu_i, double mu_o) const;
};

}  // namespace ofl
