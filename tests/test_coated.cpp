// The wet-tissue coating: Fresnel, the energy balance of the layered BSDF (white furnace), and the
// same furnace through the whole renderer (BSDF sampling, lane events, internal bounces).
#include <gtest/gtest.h>

#include <cmath>

#include "materials/interfaces/coated.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/trace/sampling.h"
#include "renderer/spectral/spectra/units.h"

using namespace ofl;

TEST(Coated, FresnelKnownValues) {
  // Normal incidence ((n-1)/(n+1))^2, Brewster angle zero p-reflectance (s stays), TIR above the
  // critical angle from inside.
  EXPECT_NEAR(fresnel_dielectric(1.0, 1.5), 0.04, 1e-12);
  EXPECT_NEAR(fresnel_dielectric(1.0, 1.33), std::pow(0.33 / 2.33, 2), 1e-12);
  double crit = std::sqrt(1 - 1 / (1.33 * 1.33));  // cos of the critical angle from inside
  EXPECT_EQ(fresnel_dielectric(crit * 0.99, 1 / 1.33), 1.0);
  EXPECT_LT(fresnel_dielectric(crit * 1.01, 1 / 1.33), 1.0);
}

namespace {
// Directional albedo of the layered BSDF with a white base (A = rho) by Monte Carlo with the
// same mixture sampling the renderer uses.
double layered_albedo(const GgxCoating& c, double mu, double rho, int n, uint64_t seed) {
  glm::dvec3 wo(std::sqrt(1 - mu * mu), 0, mu);
  double p_spec = std::clamp(c.specular_albedo(mu), 0.1, 0.9);
  double rho_eff = rho * (1 - c.internal_reflectance) / (1 - rho * c.internal_reflectance);
  Rng rng(seed, 1);
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    glm::dvec3 wi = rng.next_double() < p_spec ? c.sample(wo, rng.next_double(), rng.next_double())
                                               : sample_cosine_hemisphere(rng.next_double(), rng.next_double());
    if (wi.z <= 0) continue;
    double pdf = p_spec * c.pdf(wo, wi) + (1 - p_spec) * wi.z / kPi;
    double f = c.eval(wo, wi) + c.diffuse_kernel(wi.z, mu) * rho_eff;
    sum += f * wi.z / pdf;
  }
  return sum / n;
}
}  // namespace

TEST(Coated, WhiteFurnaceNeverCreatesEnergy) {
  for (double alpha : {0.02, 0.15, 0.4, 0.8}) {
    GgxCoating c;
    c.prepare(1.33, alpha);
    for (double mu : {0.05, 0.2, 0.5, 0.8, 1.0}) {
      double a = layered_albedo(c, mu, 1.0, 200000, 3);
      // A white base absorbs nothing: albedo 1 up to the table's accuracy, never above.
      EXPECT_LT(a, 1.01) << "alpha " << alpha << " mu " << mu;
      EXPECT_GT(a, 0.97) << "alpha " << alpha << " mu " << mu;
      double grey = layered_albedo(c, mu, 0.5, 200000, 4);
      double expect = c.specular_albedo(mu) + (1 - c.specular_albedo(mu)) * 0.5 * (1 - c.internal_reflectance) / (1 - 0.5 * c.internal_reflectance);
      EXPECT_NEAR(grey, expect, 0.01) << "alpha " << alpha << " mu " << mu;
    }
  }
}

TEST(Coated, InternalReflectanceOfWater) {
  // Hemispherical internal reflectance of a smooth n = 1.33 interface for diffuse light: about 0.47
  // (1 - (1 - 0.066) / 1.33^2), dominated by total internal reflection.
  GgxCoating c;
  c.prepare(1.33, 0.1);
  EXPECT_NEAR(c.internal_reflectance, 1 - (1 - 0.0663) / (1.33 * 1.33), 0.003);
}

// A small coated sphere with a white base inside a large black sphere that emits 1 W sr^-1 m^-2
// nm^-1 uniformly: every pixel of the small sphere must show its directional albedo, close to 1.
namespace {
double furnace_mean(double regularize) {
  nlohmann::json j = {{"format", "oralfluor-scene"}, {"version", 1},
                      {"integrator", {{"spp", 64}, {"max_depth", 20}, {"wavelengths", {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", 10}}},
                                      {"output_bands", {{"min_nm", 450}, {"max_nm", 650}, {"step_nm", 100}}}}},
                      {"camera", {{"position", {0, 0, 3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 40}, {"resolution", {48, 48}}}},
                      {"materials", {{"sky", {{"type", "lambertian"}, {"reflectance", 0.0}, {"emission", 1.0}}},
                                     {"wet", {{"type", "coated"}, {"roughness", 0.2}, {"base", {{"type", "lambertian"}, {"reflectance", 1.0}}}}}}},
                      {"geometry", {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 100}, {"material", "sky"}},
                                    {{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 0.8}, {"material", "wet"}}}}};
  j["integrator"]["regularize_glossy"] = regularize;
  Scene sc = load_scene(JsonFile::from(j, "furnace.json"));
  RenderResult r = render(sc);
  double sum = 0, mx = 0;
  int n = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      double dx = (x + 0.5 - 24) / 24, dy = (y + 0.5 - 24) / 24;
      // Pixels well inside the sphere's silhouette (radius 0.8 at distance 3, fov 40).
      if (dx * dx + dy * dy > 0.6 * 0.6) continue;
      for (int b = 0; b < r.image.bands(); ++b) {
        double v = r.image.pixel(x, y)[b];
        sum += v;
        mx = std::max(mx, v);
        ++n;
      }
    }
  double mean = sum / n;
  EXPECT_LT(mx, 2.0);
  // The sky seen directly around the sphere is 1 (only wavelength-sampling noise).
  double sky = 0;
  int ns = 0;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 48; ++x, ++ns) sky += r.image.pixel(x, y)[1];
  EXPECT_NEAR(sky / ns, 1.0, 0.01);
  return mean;
}
}  // namespace

TEST(Coated, RenderedWhiteFurnace) {
  EXPECT_NEAR(furnace_mean(0.0), 1.0, 0.02);
  // Path regularisation swaps in a rougher (still energy-conserving) lobe after diffuse bounces.
  EXPECT_NEAR(furnace_mean(0.6), 1.0, 0.02);
}
