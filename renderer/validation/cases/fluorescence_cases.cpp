// Closed-form cases with fluorescence (docs/transport.md, "How it is checked"). Transport is in photon
// units, so the references are computed in photons and converted to W at the end:
//   patch:  L_q(em) = [R(em) E_q(em) + sum_ex Phi(em, ex) E_q(ex) dlambda] / pi
//   sphere: L_q = (I - A)^-1 Le_q with A = diag(R) + Phi dlambda.
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <glm/geometric.hpp>

#include "renderer/validation/harness/bench_support.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {
using nlohmann::json;
using namespace bench;

// Sum of c_k Phi_k (per nm) of a material on the grid, row em, column ex.
Eigen::MatrixXd mixture_eem(const Scene& sc, const Material& m) {
  int n = sc.grid().size();
  Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(n, n);
  for (auto& f : m.fluorophores)
    for (int em = 0; em < n; ++em)
      for (int ex = 0; ex < n; ++ex) phi(em, ex) += f.concentration * sc.eems[f.eem].at(em, ex);
  return phi;
}

std::vector<double> photons_to_watts(const Scene& sc, const Eigen::VectorXd& q) {
  std::vector<double> w(q.size());
  for (int i = 0; i < q.size(); ++i) w[i] = q(i) * photon_energy_J(sc.grid().wavelength(i));
  return w;
}

json tongue_reflectance() {
  return {{"type", "points"}, {"points", {{350, 0.18}, {450, 0.20}, {540, 0.16}, {580, 0.25}, {620, 0.45}, {750, 0.6}}}};
}

}  // namespace

namespace {

json fluorescent_patch_material() {
  return {{"type", "fluorescent"}, {"reflectance", tongue_reflectance()},
          {"fluorophores", {{{"name", "NADH"}, {"concentration", 0.05}},
                            {{"name", "FAD"}, {"concentration", 0.08}},
                            {{"name", "collagen"}, {"concentration", 0.05}}}}};
}

// The fluorescent patch under a tilted point LED, with any material whose Lambertian albedo matrix
// (reflectance + fluorophores of the scene's Material) is the reference.
BenchResult patch_case(const BenchOptions& o, const std::string& name, const json& material, bool narrow) {
  json j = base_scene(o, 1, 350, 750);
  glm::dvec3 lp(0.02, 0.01, 0.06), target(-0.01, 0.0, 0.0);
  j["camera"] = {{"position", {0, 0, 0.25}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 24}, {"resolution", {96, 96}}};
  j["materials"] = {{"patch", material}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.4, 0, 0}}, {"v", {0, 0.4, 0}}, {"material", "patch"}}};
  json spd = narrow ? json{{"type", "gaussian"}, {"peak_nm", 385}, {"fwhm_nm", 10}} : json{{"type", "blackbody"}, {"temperature_K", 6500}};
  j["lights"] = {{{"type", "led"}, {"spd", spd}, {"radiant_intensity_W_sr", 0.5}, {"profile", {{"half_angle_deg", 30}}},
                  {"position", {lp.x, lp.y, lp.z}}, {"target", {target.x, target.y, target.z}}}};
  Rendered r = render_json(j, name);
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  const Material& m = sc.materials[0];
  int n = sc.grid().size();
  // Radiance per unit irradiance factor (P cos / r^2), in photon units, then converted to W.
  Eigen::VectorXd Eq(n);
  for (int i = 0; i < n; ++i) Eq(i) = led.spectral_photons[i];
  Eigen::MatrixXd phi = mixture_eem(sc, m) * sc.grid().step_nm;
  Eigen::VectorXd Lq = (phi * Eq) / kPi;
  for (int i = 0; i < n; ++i) Lq(i) += m.reflectance[i] * Eq(i) / kPi;
  auto lb = to_bands(sc, photons_to_watts(sc, Lq));
  Reference ref = plane_reference(sc, point_led_on_plane(led, lb), nullptr);
  glm::dvec3 a = led.axis;
  auto px = pixel_of(sc.camera, led.position + (-led.position.z / a.z) * a);
  auto b = compare(name, sc, r.result.image, ref,
                   {{"on-axis", {px[0] - 4, px[1] - 4, px[0] + 4, px[1] + 4}}, {"whole", {0, 0, sc.camera.width, sc.camera.height}}});
  // The fluorescence layer against the fluorescent part of the closed form, whole image.
  {
    auto fb = to_bands(sc, photons_to_watts(sc, (phi * Eq) / kPi));
    const auto& img = r.result.image;
    int B = img.bands();
    std::vector<double> m(B, 0.0), mr(B, 0.0);
    for (size_t p = 0; p < size_t(img.width) * img.height; ++p) {
      if (!ref.valid[p]) continue;
      double scale = 0;  // geometric factor of this pixel = ref / lb for any band with lb > 0
      for (int k = 0; k < B; ++k)
        if (lb[k] > 0) { scale = ref.L[p * B + k] / lb[k]; break; }
      for (int k = 0; k < B; ++k) { m[k] += img.fluorescence.empty() ? 0.0 : img.fluorescence[p * B + k]; mr[k] += fb[k] * scale; }
    }
    double worst = 0;
    for (int k = 0; k < B; ++k)
      if (mr[k] > 1e-3 * *std::max_element(mr.begin(), mr.end())) worst = std::max(worst, std::fabs(m[k] - mr[k]) / mr[k]);
    b.extra["fluorescence_layer_max_band_error"] = worst;
  }
  // Share of the signal that is fluorescence, to show what the case tests.
  double fl = 0, tot = 0;
  for (int i = 0; i < n; ++i) {
    double e = photon_energy_J(sc.grid().wavelength(i));
    fl += (phi * Eq)(i) * e;
    tot += ((phi * Eq)(i) + m.reflectance[i] * Eq(i)) * e;
  }
  b.extra["fluorescence_share_of_radiance"] = fl / tot;
  return finish(b, r, o);
}

}  // namespace

BenchResult fluorescent_patch(const BenchOptions& o, bool narrow) {
  return patch_case(o, narrow ? "fluorescent_patch_385" : "fluorescent_patch", fluorescent_patch_material(), narrow);
}

// The thin-layer limit: the same fluorescent surface as the opaque base of a layered stack whose one
// layer (index 1, absorbing and scattering) is 1 nm thick must give the surface material's closed
// form; it exercises the stack's walk, its next-event connection to the base and the base's summed
// direct excitation through the layer's transmittance.
BenchResult layered_thin_limit(const BenchOptions& o) {
  json base = fluorescent_patch_material();
  base["type"] = "base";
  json m = {{"type", "layered_tissue"}, {"transport", "walk"},
            {"layers", {{{"name", "film"}, {"thickness_mm", 1e-6}, {"ior", 1.0},
                         {"scattering", {{"g", 0.5}, {"mus_per_mm", 5.0}}}, {"absorption", {{"baseline_per_mm", 2.0}}}}}},
            {"bottom", base}};
  return patch_case(o, "layered_thin_limit", m, false);
}

BenchResult fluorescent_sphere(const BenchOptions& o) {
  json j = base_scene(o, 100000, 350, 750);
  j["camera"] = {{"position", {0, 0, 0}}, {"look_at", {1, 0.2, 0.1}}, {"up", {0, 0, 1}}, {"fov_deg", 90}, {"resolution", {32, 32}}};
  // Violet-blue emission excites NADH (emits ~460 nm), whose light excites FAD (emits ~525 nm).
  j["materials"] = {{"wall", {{"type", "fluorescent"},
                              {"reflectance", {{"type", "points"}, {"points", {{350, 0.3}, {500, 0.5}, {750, 0.6}}}}},
                              {"fluorophores", {{{"name", "NADH"}, {"concentration", 0.3}}, {{"name", "FAD"}, {"concentration", 0.4}}}},
                              {"emission", {{"type", "product"}, {"factors", {{{"type", "gaussian"}, {"peak_nm", 370}, {"fwhm_nm", 30}}, 1.0}}}}}}};
  // A weak broadband emission keeps every output band measurable.
  j["materials"]["wall"]["emission"] = {{"type", "points"}, {"points", {{350, 1.0}, {380, 1.0}, {400, 0.02}, {750, 0.02}}}};
  j["geometry"] = {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"material", "wall"}}};
  j["lights"] = json::array();
  Rendered r = render_json(j, "fluorescent_sphere");
  const Scene& sc = r.scene;
  const Material& m = sc.materials[0];
  int n = sc.grid().size();
  Eigen::MatrixXd A = mixture_eem(sc, m) * sc.grid().step_nm;
  for (int i = 0; i < n; ++i) A(i, i) += m.reflectance[i];
  Eigen::VectorXd Le(n);
  for (int i = 0; i < n; ++i) Le(i) = m.emission[i] * photons_per_joule(sc.grid().wavelength(i));
  Eigen::VectorXd L = (Eigen::MatrixXd::Identity(n, n) - A).partialPivLu().solve(Le);
  auto lb = to_bands(sc, photons_to_watts(sc, L));
  auto b = compare("fluorescent_sphere", sc, r.result.image, uniform_reference(sc, lb), {{"whole", {0, 0, sc.camera.width, sc.camera.height}}});
  // How much the cascade matters: the answer without fluorescence excited by fluorescence
  // (one fluorescent step, reflections otherwise) differs from the full solution by this much.
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) D(i, i) = 1.0 / (1.0 - m.reflectance[i]);
  Eigen::MatrixXd Phi = A;
  for (int i = 0; i < n; ++i) Phi(i, i) = 0;
  Eigen::VectorXd one_step = D * Le + D * Phi * D * Le;
  auto ob = to_bands(sc, photons_to_watts(sc, one_step));
  double worst = 0;
  for (size_t k = 0; k < lb.size(); ++k) worst = std::max(worst, std::fabs(ob[k] - lb[k]) / lb[k]);
  b.extra["cascade_effect_max_band"] = worst;
  b.extra["max_photon_albedo"] = A.colwise().sum().maxCoeff();
  return finish(b, r, o);
}

BenchResult reradiation_only(const BenchOptions& o) {
  json j = base_scene(o, 1, 380, 720, 5);
  j["integrator"]["output_bands"] = {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", 5}};
  j["camera"] = {{"position", {0, 0, 0.25}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 24}, {"resolution", {48, 48}}};
  j["materials"] = {{"patch", {{"type", "fluorescent"}, {"reflectance", 0.0},
                               {"fluorophores", {{{"name", "FAD"}, {"concentration", 0.3}}, {{"name", "NADH"}, {"concentration", 0.3}}}}}}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.4, 0, 0}}, {"v", {0, 0.4, 0}}, {"material", "patch"}}};
  // A triangular line with compact support 420-430 nm: no light below 420 nm at all.
  j["lights"] = {{{"type", "led"}, {"spd", {{"type", "points"}, {"points", {{420, 0.0}, {425, 1.0}, {430, 0.0}}}}}, {"radiant_intensity_W_sr", 0.5},
                  {"profile", {{"cos_power", 1}}}, {"position", {0, 0, 0.05}}, {"axis", {0, 0, -1}}}};
  Rendered r = render_json(j, "reradiation_only");
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  int n = sc.grid().size();
  int lowest = -1;
  for (int i = 0; i < n && lowest < 0; ++i)
    if (led.spectral_photons[i] > 0) lowest = i;
  Eigen::VectorXd Eq(n);
  for (int i = 0; i < n; ++i) Eq(i) = led.spectral_photons[i];
  Eigen::VectorXd Lq = mixture_eem(sc, sc.materials[0]) * sc.grid().step_nm * Eq / kPi;
  auto lb = to_bands(sc, photons_to_watts(sc, Lq));
  auto b = compare("reradiation_only", sc, r.result.image, plane_reference(sc, point_led_on_plane(led, lb), nullptr), {{"whole", {0, 0, sc.camera.width, sc.camera.height}}});
  // Output bands are the grid bins here; every band at or below the lowest excitation bin must be 0.
  double lowest_nm = sc.grid().wavelength(lowest);
  double below = 0, above = 0;
  const auto& img = r.result.image;
  for (size_t p = 0; p < size_t(img.width) * img.height; ++p)
    for (int k = 0; k < img.bands(); ++k) {
      double v = img.data[p * img.bands() + k];
      if (img.band_nm[k] <= lowest_nm) below = std::max(below, std::fabs(v));
      else above = std::max(above, v);
    }
  b.extra["lowest_excitation_nm"] = lowest_nm;
  b.extra["max_radiance_at_or_below_excitation"] = below;
  b.extra["max_radiance_above_excitation"] = above;
  return finish(b, r, o);
}

BenchResult fluorescent_disk_led(const BenchOptions& o) {
  json mat = {{"type", "fluorescent"}, {"reflectance", tongue_reflectance()},
              {"fluorophores", {{{"name", "FAD"}, {"concentration", 0.3}}, {{"name", "collagen"}, {"concentration", 0.2}}}}};
  return disk_led_case(o, "fluorescent_disk_led", mat, [](const Scene& sc) {
    const LedLight& led = sc.lights[0];
    const Material& m = sc.materials[0];
    int n = sc.grid().size();
    Eigen::VectorXd Lq(n);
    for (int i = 0; i < n; ++i) Lq(i) = led.spectral_photons[i] / led.area();
    Eigen::VectorXd out = mixture_eem(sc, m) * sc.grid().step_nm * Lq;
    for (int i = 0; i < n; ++i) out(i) += m.reflectance[i] * Lq(i);
    return photons_to_watts(sc, out / kPi);
  });
}

}  // namespace ofl
