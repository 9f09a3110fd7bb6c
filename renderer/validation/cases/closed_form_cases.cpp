#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/validation/harness/bench_support.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/render/trace/sampling.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {

using nlohmann::json;
using namespace bench;

json tongue_like_reflectance() {
  return {{"type", "points"}, {"points", {{380, 0.20}, {450, 0.20}, {540, 0.16}, {580, 0.25}, {620, 0.50}, {720, 0.65}}}};
}


// Case 1: Lambertian patch under a point LED with a cos^m profile, tilted so that on- and
// off-axis pixels see different angles: L = R E / pi, E = I0 S P(theta) cos(theta_i) / r^2.
BenchResult lambert_point_led(const BenchOptions& o) {
  json j = base_scene(o, 1);
  glm::dvec3 lp(0.02, 0.01, 0.06), target(-0.01, 0.0, 0.0);
  j["camera"] = {{"position", {0, 0, 0.25}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 24}, {"resolution", {96, 96}}};
  j["materials"] = {{"patch", {{"type", "lambertian"}, {"reflectance", tongue_like_reflectance()}}}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.4, 0, 0}}, {"v", {0, 0.4, 0}}, {"material", "patch"}}};
  j["lights"] = {{{"type", "led"}, {"spd", {{"type", "blackbody"}, {"temperature_K", 4000}}}, {"radiant_intensity_W_sr", 0.5},
                  {"profile", {{"half_angle_deg", 30}}}, {"position", {lp.x, lp.y, lp.z}}, {"target", {target.x, target.y, target.z}}}};
  Rendered r = render_json(j, "lambert_point_led");
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  auto RS = sc.materials[0].reflectance;
  for (size_t i = 0; i < RS.size(); ++i) RS[i] *= led.spectral_intensity[i] / kPi;
  auto rs_bands = to_bands(sc, RS);
  Reference ref = plane_reference(sc, point_led_on_plane(led, rs_bands), nullptr);
  // Pixel where the LED axis meets the patch, for an on-axis region.
  glm::dvec3 a = led.axis;
  glm::dvec3 hit = led.position + (-led.position.z / a.z) * a;
  const auto& c = sc.camera;
  double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0);
  int px = int((hit.x / (c.position.z * th) + 1) * 0.5 * c.width), py = int((1 - hit.y / (c.position.z * th)) * 0.5 * c.height);
  auto b = compare("lambert_point_led", sc, r.result.image, ref,
                   {{"on-axis", {px - 4, py - 4, px + 4, py + 4}}, {"whole", {0, 0, c.width, c.height}}});
  // The irradiance plane (pixel-centre rays, deterministic) against E = I0 P(theta) cos(theta_i) / r^2.
  const auto& irr = r.result.image.aovs.at("aov.irradiance");
  double worst = 0;
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      glm::dvec3 d = pinhole_dir(c, x + 0.5, y + 0.5);
      glm::dvec3 p = c.position + (-c.position.z / d.z) * d;
      glm::dvec3 to = p - led.position;
      double r2 = glm::dot(to, to);
      glm::dvec3 w = to / std::sqrt(r2);
      double e = led.intensity_W_sr * led.profile.eval(glm::dot(w, led.axis)) * (-w.z) / r2;
      worst = std::max(worst, std::fabs(irr[size_t(y) * c.width + x] - e) / e);
    }
  b.extra["aov_irradiance_max_rel_error"] = worst;
  return finish(b, r, o);
}

// pbrt-v4's spot shape as an angle table (0.5 degree steps): 1 inside `inner`, smoothstep in cos
// down to 0 at `outer`, 0 beyond.
json spot_profile(double inner_deg, double outer_deg) {
  json rows = json::array();
  const double ci = std::cos(inner_deg * kPi / 180), co = std::cos(outer_deg * kPi / 180);
  for (int i = 0; i <= 180; ++i) {
    const double c = std::cos(i * 0.5 * kPi / 180), t = std::clamp((c - co) / (ci - co), 0.0, 1.0);
    rows.push_back({i * 0.5, t * t * (3 - 2 * t)});
  }
  return {{"table", rows}};
}

// Unoccluded irradiance per unit I0 S(lambda) of a disk LED at a point of the plane z = 0 (normal
// +z), by a 16 x 16 midpoint rule over the disk: the mean over the disk of P(theta) cos / r^2.
double disk_irradiance_on_plane(const LedLight& led, const glm::dvec3& p) {
  const int n = 16;
  double sum = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      glm::dvec2 d = sample_concentric_disk((a + 0.5) / n, (b + 0.5) / n) * led.radius_m;
      glm::dvec3 q = led.position + d.x * led.tangent + d.y * led.bitangent;
      glm::dvec3 to = p - q;
      double r2 = glm::dot(to, to);
      glm::dvec3 w = to / std::sqrt(r2);
      if (w.z < 0) sum += led.profile.eval(glm::dot(w, led.axis)) * (-w.z) / r2;
    }
  return sum / (n * n);
}

// Several spot LEDs (pbrt-v4's cone shape, tabulated) whose cones each cover part of a Lambertian
// patch, of two spectra, one a disk, one facing away: L = R / pi sum_i I0_i S_i P_i cos / r^2.
// Where a cone does not reach, that LED is never chosen for next-event estimation
// (renderer/render/trace/light_choice.h); the answer must not change at the cone edges.
BenchResult spot_leds(const BenchOptions& o) {
  json j = base_scene(o, 1);
  j["camera"] = {{"position", {0, 0, 0.25}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 24}, {"resolution", {96, 96}}};
  j["materials"] = {{"patch", {{"type", "lambertian"}, {"reflectance", tongue_like_reflectance()}}}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.4, 0, 0}}, {"v", {0, 0.4, 0}}, {"material", "patch"}}};
  const json warm = {{"type", "blackbody"}, {"temperature_K", 3500}};
  auto led = [&](json spd, double i0, json profile, std::array<double, 3> pos, std::array<double, 3> target, double radius) {
    return json{{"type", "led"}, {"spd", spd}, {"radiant_intensity_W_sr", i0}, {"profile", profile}, {"radius_m", radius},
                {"position", pos}, {"target", target}};
  };
  j["lights"] = {led(1.0, 0.3, spot_profile(15, 20), {0.03, 0.02, 0.06}, {0.0, 0.01, 0.0}, 0.0),
                 led(warm, 0.5, spot_profile(10, 14), {-0.04, -0.01, 0.07}, {-0.02, -0.02, 0.0}, 0.0),
                 led(warm, 0.4, spot_profile(20, 25), {0.0, -0.08, 0.05}, {0.02, 0.0, 0.0}, 0.006),  // outside the view
                 led(1.0, 1.0, {{"half_angle_deg", 30}}, {0.0, 0.0, 0.04}, {0.0, 0.0, 0.1}, 0.0)};  // faces away
  Rendered r = render_json(j, "spot_leds");
  const Scene& sc = r.scene;
  std::vector<std::vector<double>> per_light;  // R S_i I0_i / pi in bands
  for (const LedLight& l : sc.lights) {
    std::vector<double> v(sc.grid().size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = sc.materials[0].reflectance[i] * l.spectral_intensity[i] / kPi;
    per_light.push_back(to_bands(sc, v));
  }
  auto f = [&](const glm::dvec3& p, std::vector<double>& out) {
    std::fill(out.begin(), out.end(), 0.0);
    for (size_t i = 0; i < sc.lights.size(); ++i) {
      const LedLight& l = sc.lights[i];
      double e = 0;
      if (l.is_point()) {
        glm::dvec3 to = p - l.position;
        double r2 = glm::dot(to, to);
        glm::dvec3 d = to / std::sqrt(r2);
        e = d.z < 0 ? l.profile.eval(glm::dot(d, l.axis)) * (-d.z) / r2 : 0.0;
      } else {
        e = disk_irradiance_on_plane(l, p);
      }
      for (size_t b = 0; b < out.size(); ++b) out[b] += per_light[i][b] * e;
    }
    return true;
  };
  // Compared where the LEDs give at least 1 % of the brightest pixel: the relative error of a
  // pixel at the far end of a cone edge says little (its reference is nearly 0).
  Reference ref = plane_reference(sc, f, nullptr);
  const int B = sc.integrator.bands.size();
  std::vector<double> sums(ref.valid.size(), 0.0);
  for (size_t px = 0; px < ref.valid.size(); ++px)
    for (int b = 0; b < B; ++b) sums[px] += ref.L[px * B + b];
  const double brightest = *std::max_element(sums.begin(), sums.end());
  for (size_t px = 0; px < ref.valid.size(); ++px)
    if (!(sums[px] >= 0.01 * brightest)) ref.valid[px] = 0;
  const auto& c = sc.camera;
  auto b = compare("spot_leds", sc, r.result.image, ref, {{"whole", {0, 0, c.width, c.height}}});
  return finish(b, r, o);
}

// The flat patch of shared/bench/README.md: a 10 x 10 cm Lambertian square (R = 0.5) under an
// isotropic point light 10 cm above its centre, seen from 30 cm with an 18 degree field of view:
// L = (R / pi) I h / r^3 with r the distance from the light to the surface point.
BenchResult flatpatch(const BenchOptions& o) {
  json j = base_scene(o, 1);
  j["camera"] = {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 18}, {"resolution", {128, 128}}};
  j["materials"] = {{"patch", {{"type", "lambertian"}, {"reflectance", 0.5}}}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.1, 0, 0}}, {"v", {0, 0.1, 0}}, {"material", "patch"}}};
  j["lights"] = {{{"type", "led"}, {"spd", 1.0}, {"radiant_intensity_W_sr", 1.0}, {"profile", {{"cos_power", 0}}},
                  {"position", {0, 0, 0.1}}, {"axis", {0, 0, -1}}}};
  Rendered r = render_json(j, "flatpatch");
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  std::vector<double> per(sc.grid().size());
  for (size_t i = 0; i < per.size(); ++i) per[i] = 0.5 / kPi * led.spectral_intensity[i];
  auto pb = to_bands(sc, per);
  auto f = [&](const glm::dvec3& p, std::vector<double>& out) {
    if (std::fabs(p.x) > 0.05 || std::fabs(p.y) > 0.05) return false;  // off the patch
    double r = glm::length(p - led.position);
    for (size_t b = 0; b < out.size(); ++b) out[b] = pb[b] * 0.1 / (r * r * r);
    return true;
  };
  const auto& c = sc.camera;
  auto b = compare("flatpatch", sc, r.result.image, plane_reference(sc, f, nullptr),
                   {{"centre", {c.width / 2 - 4, c.height / 2 - 4, c.width / 2 + 4, c.height / 2 + 4}}, {"whole", {0, 0, c.width, c.height}}});
  return finish(b, r, o);
}

// Case 4: a Lambertian disk LED (m = 1, radius a) above a patch; irradiance of a point of a
// parallel plane at distance h and radial offset rho: E = pi L / 2 (1 - (h^2 + rho^2 - a^2) /
// sqrt((h^2 + rho^2 + a^2)^2 - 4 rho^2 a^2)); on the axis this is E = pi L a^2 / (h^2 + a^2).
// `spectrum` gives, per grid bin, the patch radiance in W per unit of that geometric factor
// (E / L_led): R L_led / pi for a Lambertian patch, more with fluorescence.
}  // namespace

BenchResult disk_led_case(const BenchOptions& o, const std::string& name, const nlohmann::json& material,
                          const std::function<std::vector<double>(const Scene&)>& spectrum) {
  json j = base_scene(o, 1, 350, 750);
  const double h = 0.03, a = 0.015;
  j["camera"] = {{"position", {0.12, 0, 0.16}}, {"look_at", {0, 0, 0}}, {"up", {0, 0, 1}}, {"fov_deg", 20}, {"resolution", {96, 96}}};
  j["materials"] = {{"patch", material}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.5, 0, 0}}, {"v", {0, 0.5, 0}}, {"material", "patch"}}};
  json spd = material.value("type", "") == "lambertian" ? json{{"type", "gaussian"}, {"peak_nm", 560}, {"fwhm_nm", 200}}
                                                        : json{{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}};
  j["lights"] = {{{"type", "led"}, {"spd", spd}, {"radiant_intensity_W_sr", 0.3},
                  {"profile", {{"cos_power", 1}}}, {"radius_m", a}, {"position", {0, 0, h}}, {"axis", {0, 0, -1}}}};
  Rendered r = render_json(j, name);
  const Scene& sc = r.scene;
  auto lb = to_bands(sc, spectrum(sc));
  auto f = [&](const glm::dvec3& p, std::vector<double>& out) {
    double rho2 = p.x * p.x + p.y * p.y;
    double e = 0.5 * kPi * (1 - (h * h + rho2 - a * a) / std::sqrt((h * h + rho2 + a * a) * (h * h + rho2 + a * a) - 4 * rho2 * a * a));
    for (size_t b = 0; b < out.size(); ++b) out[b] = lb[b] * e;
    return true;
  };
  // Camera rays that pass through the LED disk see the LED, not the patch.
  auto blocked = [&](const glm::dvec3& o, const glm::dvec3& p) {
    double t = (h - o.z) / (p.z - o.z);
    glm::dvec3 q = o + t * (p - o);
    return q.x * q.x + q.y * q.y <= a * a * 1.05;
  };
  Reference ref = plane_reference(sc, f, blocked);
  const auto& c = sc.camera;
  int cx = c.width / 2, cy = c.height / 2;
  auto b = compare(name, sc, r.result.image, ref, {{"on-axis", {cx - 3, cy - 3, cx + 3, cy + 3}}, {"whole", {0, 0, c.width, c.height}}});
  return finish(b, r, o);
}

namespace {

BenchResult disk_led(const BenchOptions& o) {
  return disk_led_case(o, "disk_led", {{"type", "lambertian"}, {"reflectance", 0.6}}, [](const Scene& sc) {
    const LedLight& led = sc.lights[0];
    double area = sc.lights[0].area();
    std::vector<double> v(sc.grid().size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = sc.materials[0].reflectance[i] * led.spectral_intensity[i] / area / kPi;
    return v;
  });
}

// Case 3: inside a closed Lambertian sphere of reflectance R that emits Le uniformly, the
// radiance is L = Le / (1 - R) everywhere (multiple bounces, energy conservation).
BenchResult closed_sphere(const BenchOptions& o) {
  json j = base_scene(o, 100000);
  j["camera"] = {{"position", {0, 0, 0}}, {"look_at", {1, 0.2, 0.1}}, {"up", {0, 0, 1}}, {"fov_deg", 90}, {"resolution", {48, 48}}};
  j["materials"] = {{"wall", {{"type", "lambertian"}, {"reflectance", {{"type", "points"}, {"points", {{380, 0.3}, {550, 0.8}, {720, 0.5}}}}},
                              {"emission", {{"type", "points"}, {"points", {{380, 0.5}, {720, 1.5}}}}}}}};
  j["geometry"] = {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"material", "wall"}}};
  j["lights"] = json::array();
  Rendered r = render_json(j, "closed_sphere");
  const Scene& sc = r.scene;
  const Material& m = sc.materials[0];
  std::vector<double> Lg(sc.grid().size());
  for (size_t i = 0; i < Lg.size(); ++i) Lg[i] = m.emission[i] / (1 - m.reflectance[i]);
  auto lb = to_bands(sc, Lg);
  const auto& c = sc.camera;
  Reference ref;
  ref.valid.assign(size_t(c.width) * c.height, 1);
  for (int p = 0; p < c.width * c.height; ++p) ref.L.insert(ref.L.end(), lb.begin(), lb.end());
  auto b = compare("closed_sphere", sc, r.result.image, ref, {{"whole", {0, 0, c.width, c.height}}});
  return finish(b, r, o);
}

// A white furnace with a spot: inside a closed Lambertian sphere (radius 1, reflectance R) a point
// LED at the centre shines a pbrt-style spot (30/40 degrees) at part of the wall. Every bounce after
// the first spreads its light evenly over a sphere's wall, so the radiance at a wall point x is
// L = R / pi [I0 S P(theta_x) / r^2 + R Phi / (A (1 - R))], Phi = I0 S int P dOmega, A = 4 pi r^2.
// The view crosses the cone's edge: wall points outside it get no light sample at all (the LED's
// weight there is 0, renderer/render/trace/light_choice.h), only the many-bounce light from inside it.
BenchResult spot_furnace(const BenchOptions& o) {
  json j = base_scene(o, 100000);
  j["camera"] = {{"position", {0, 0, 0}}, {"look_at", {1, 0.55, 0.1}}, {"up", {0, 0, 1}}, {"fov_deg", 90}, {"resolution", {48, 48}}};
  j["materials"] = {{"wall", {{"type", "lambertian"}, {"reflectance", {{"type", "points"}, {"points", {{380, 0.6}, {550, 0.85}, {720, 0.7}}}}}}}};
  j["geometry"] = {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"material", "wall"}}};
  j["lights"] = {{{"type", "led"}, {"spd", 1.0}, {"radiant_intensity_W_sr", 2.0}, {"profile", spot_profile(30, 40)},
                  {"position", {0, 0, 0}}, {"axis", {1, 0, 0}}}};
  Rendered r = render_json(j, "spot_furnace");
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  const double omega = led.profile.solid_angle_integral(), area = 4 * kPi;
  std::vector<double> direct(sc.grid().size()), diffuse(sc.grid().size());
  for (size_t i = 0; i < direct.size(); ++i) {
    const double R = sc.materials[0].reflectance[i], I = led.spectral_intensity[i];
    direct[i] = R / kPi * I;
    diffuse[i] = R / kPi * R * I * omega / (area * (1 - R));
  }
  const auto db = to_bands(sc, direct), fb = to_bands(sc, diffuse);
  const auto& c = sc.camera;
  const int B = sc.integrator.bands.size();
  Reference ref;
  ref.valid.assign(size_t(c.width) * c.height, 1);
  ref.L.assign(size_t(c.width) * c.height * B, 0.0);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x)
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          const glm::dvec3 d = pinhole_dir(c, x + (sx + 0.5) / 4, y + (sy + 0.5) / 4);  // the wall point, r = 1
          const double prof = led.profile.eval(glm::dot(d, led.axis));
          for (int b = 0; b < B; ++b) ref.L[(size_t(y) * c.width + x) * B + b] += (db[b] * prof + fb[b]) / 16.0;
        }
  const glm::dvec3 in_cone = led.position + led.axis, out_of_cone = glm::normalize(glm::dvec3(1, 1.2, 0.1));
  const auto pi = pixel_of(c, in_cone), po = pixel_of(c, out_of_cone);
  auto b = compare("spot_furnace", sc, r.result.image, ref,
                   {{"whole", {0, 0, c.width, c.height}},
                    {"inside the cone", {pi[0] - 3, pi[1] - 3, pi[0] + 3, pi[1] + 3}},
                    {"outside the cone", {po[0] - 3, po[1] - 3, po[0] + 3, po[1] + 3}}});
  return finish(b, r, o);
}

}  // namespace

nlohmann::json BenchResult::to_json() const {
  json regs = json::array();
  for (auto& r : regions) regs.push_back({{"name", r.name}, {"rel_error", r.rel_error}, {"max_band_error", r.max_band_error}, {"pixels", r.pixels}});
  return {{"case", name}, {"spp", spp}, {"mean_rel_error", mean_rel_error}, {"max_rel_error", max_rel_error},
          {"rms_pixel_rel_error", rms_pixel_rel_error}, {"seconds", seconds},
          {"camera_samples_per_second", camera_samples_per_second}, {"regions", regs}, {"details", extra}};
}

std::vector<BenchCaseInfo> bench_cases() {
  return {
      {"lambert_point_led", "Lambertian patch under a tilted point LED with a cos^m profile (30 deg half-angle): L = R I0 S P(theta) cos(theta_i) / (pi r^2), on- and off-axis pixels", 256},
      {"flatpatch", "the flat patch of shared/bench/README.md: R = 0.5 square under an isotropic point light 10 cm above: L = (R / pi) I h / r^3", 256},
      {"disk_led", "Lambertian disk LED (radius 15 mm, 30 mm above a patch): E = pi L a^2 / (h^2 + a^2) on axis and the parallel-plane disk formula off axis; checks MIS", 256},
      {"spot_leds", "Lambertian patch under four spot LEDs (pbrt-v4's cone shape as tables; two spectra; one a disk; one facing away) whose cones cover parts of it: L = R / pi sum_i I0_i S_i P_i cos / r^2; checks light selection by what each LED can give a point", 256},
      {"spot_furnace", "white furnace with a spot: a point spot LED (30/40 deg) at the centre of a closed Lambertian sphere, the view across its cone's edge: L = R / pi [I0 S P(theta) + R Phi / (4 pi (1 - R))] (light selection where the LED reaches no point, many bounces, Russian roulette)", 256},
      {"closed_sphere", "camera inside a closed emitting Lambertian sphere: L = Le / (1 - R) per wavelength (multiple bounces, Russian roulette)", 256},
      {"fluorescent_patch", "fluorescent patch (R + NADH + FAD + collagen) under a tilted broadband point LED: L(em) = [R E(em) + sum_ex Phi(em, ex) E(ex) dlambda] / pi in photon units", 256},
      {"fluorescent_patch_385", "the fluorescent patch under a narrow 385 nm LED whose light lies far below the emission bands", 256},
      {"fluorescent_disk_led", "fluorescent patch under a violet Lambertian disk LED: the disk formula with L(em) = [R L(em) + sum_ex Phi(em, ex) L(ex) dlambda] / pi; checks how next-event estimation and BSDF hits of the LED share fluorescent paths", 256},
      {"fluorescent_sphere", "closed sphere with albedo matrix A = diag(R) + Phi dlambda (NADH exciting FAD) and emission Le: L = (I - A)^-1 Le in every band (cascades, energy conservation)", 512},
      {"reradiation_only", "pure re-radiation (R = 0) under a 420-430 nm LED: exactly no radiance at or below the lowest excitation wavelength, and the closed form above it", 256},
      {"layered_thin_limit", "the fluorescent patch as the opaque base of a layered stack whose one layer is 1 nm thick: the surface material's closed form through the layered walk", 256},
      {"layered_fluorescent_slab", "a 0.3 mm non-scattering fluorescent layer (FAD) rendered under a point LED: per-pixel exponential attenuation in and out", 256},
      {"layered_fluorescent_slab_table", "the same slab with transport \"table\": the tabulated stack response against the per-pixel closed form", 256},
  };
}

BenchResult run_bench_case(const std::string& name, const BenchOptions& o) {
  if (name == "lambert_point_led") return lambert_point_led(o);
  if (name == "flatpatch") return flatpatch(o);
  if (name == "disk_led") return disk_led(o);
  if (name == "closed_sphere") return closed_sphere(o);
  if (name == "spot_leds") return spot_leds(o);
  if (name == "spot_furnace") return spot_furnace(o);
  if (name == "fluorescent_patch") return fluorescent_patch(o, false);
  if (name == "fluorescent_patch_385") return fluorescent_patch(o, true);
  if (name == "fluorescent_sphere") return fluorescent_sphere(o);
  if (name == "fluorescent_disk_led") return fluorescent_disk_led(o);
  if (name == "reradiation_only") return reradiation_only(o);
  if (name == "layered_thin_limit") return layered_thin_limit(o);
  if (name == "layered_fluorescent_slab") return layered_fluorescent_slab(o);
  if (name == "layered_fluorescent_slab_table") return layered_fluorescent_slab_table(o);
  std::string names;
  for (auto& c : bench_cases()) names += (names.empty() ? "" : ", ") + c.name;
  throw InputError("", "case \"" + name + "\"", "unknown bench case (have: " + names + ")");
}

}  // namespace ofl
