#include "renderer/bench/closed_form_cases.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/core/error.h"
#include "renderer/core/json_node.h"
#include "renderer/render/render_job.h"
#include "renderer/spectral/units.h"

namespace ofl {
namespace {

using nlohmann::json;

// Band means of a spectrum tabulated on the scene's grid (box overlap of bins with bands).
std::vector<double> to_bands(const Scene& sc, const std::vector<double>& grid_values) {
  const auto& g = sc.grid();
  const auto& bs = sc.integrator.bands;
  std::vector<double> out(bs.size(), 0.0);
  for (int b = 0; b < bs.size(); ++b) {
    double lo = bs.centre(b) - 0.5 * bs.step_nm, hi = bs.centre(b) + 0.5 * bs.step_nm;
    for (int i = 0; i < g.size(); ++i) {
      double ov = std::min(hi, g.bin_hi(i)) - std::max(lo, g.bin_lo(i));
      if (ov > 0) out[b] += grid_values[i] * ov / bs.step_nm;
    }
  }
  return out;
}

// Pinhole camera ray through image position (sx, sy) in pixels.
glm::dvec3 pinhole_dir(const CameraSpec& c, double px, double py) {
  glm::dvec3 f = glm::normalize(c.look_at - c.position);
  glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  glm::dvec3 u = glm::cross(r, f);
  double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0), tw = th * double(c.width) / c.height;
  return glm::normalize(f + (2.0 * px / c.width - 1.0) * tw * r + (1.0 - 2.0 * py / c.height) * th * u);
}

// Exact radiance at a point of the plane z = 0 (per band), or false where there is none.
using PlaneRadiance = std::function<bool(const glm::dvec3& p, std::vector<double>& bands)>;

struct Reference {
  std::vector<double> L;     // [pixel][band]
  std::vector<char> valid;   // pixels with a defined reference
};

// Averages the exact radiance over a 4x4 grid inside each pixel, looking at the plane z = 0.
Reference plane_reference(const Scene& sc, const PlaneRadiance& f, const std::function<bool(const glm::dvec3&, const glm::dvec3&)>& blocked) {
  const auto& c = sc.camera;
  int B = sc.integrator.bands.size();
  Reference ref;
  ref.L.assign(size_t(c.width) * c.height * B, 0.0);
  ref.valid.assign(size_t(c.width) * c.height, 1);
  std::vector<double> tmp(B);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      size_t p = size_t(y) * c.width + x;
      for (int sy = 0; sy < 4 && ref.valid[p]; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          glm::dvec3 d = pinhole_dir(c, x + (sx + 0.5) / 4, y + (sy + 0.5) / 4);
          if (d.z >= 0) { ref.valid[p] = 0; break; }
          double t = -c.position.z / d.z;
          glm::dvec3 hit = c.position + t * d;
          if (blocked && blocked(c.position, hit)) { ref.valid[p] = 0; break; }
          if (!f(hit, tmp)) { ref.valid[p] = 0; break; }
          for (int b = 0; b < B; ++b) ref.L[p * B + b] += tmp[b] / 16.0;
        }
    }
  return ref;
}

// Compares an image with its reference over a 3x3 grid of regions plus the whole image.
BenchResult compare(const std::string& name, const Scene& sc, const SpectralImage& img, const Reference& ref,
                    const std::vector<std::pair<std::string, std::array<int, 4>>>& extra_regions) {
  int W = img.width, H = img.height, B = img.bands();
  std::vector<std::pair<std::string, std::array<int, 4>>> regions;
  const char* rows[3] = {"top", "middle", "bottom"};
  const char* cols[3] = {"left", "centre", "right"};
  for (int ry = 0; ry < 3; ++ry)
    for (int rx = 0; rx < 3; ++rx)
      regions.push_back({std::string(rows[ry]) + "-" + cols[rx], {rx * W / 3, ry * H / 3, (rx + 1) * W / 3, (ry + 1) * H / 3}});
  for (auto& e : extra_regions) regions.push_back(e);
  BenchResult r;
  r.name = name;
  double sum = 0;
  int count = 0;
  for (auto& [rname, box] : regions) {
    std::vector<double> m(B, 0.0), mr(B, 0.0);
    int n = 0;
    for (int y = box[1]; y < box[3]; ++y)
      for (int x = box[0]; x < box[2]; ++x) {
        size_t p = size_t(y) * W + x;
        if (!ref.valid[p]) continue;
        ++n;
        for (int b = 0; b < B; ++b) { m[b] += img.data[p * B + b]; mr[b] += ref.L[p * B + b]; }
      }
    if (n == 0) continue;
    BenchRegion reg{rname, 0, 0, n};
    int nb = 0;
    for (int b = 0; b < B; ++b) {
      if (!(mr[b] > 0)) continue;
      double e = std::fabs(m[b] - mr[b]) / mr[b];
      reg.rel_error += e;
      reg.max_band_error = std::max(reg.max_band_error, e);
      sum += e;
      ++count;
      ++nb;
    }
    if (nb) reg.rel_error /= nb;
    r.max_rel_error = std::max(r.max_rel_error, reg.max_band_error);
    r.regions.push_back(reg);
  }
  r.mean_rel_error = count ? sum / count : 0;
  double s2 = 0;
  int n2 = 0;
  for (size_t p = 0; p < size_t(W) * H; ++p) {
    if (!ref.valid[p]) continue;
    for (int b = 0; b < B; ++b) {
      double lr = ref.L[p * B + b];
      if (!(lr > 0)) continue;
      double e = (img.data[p * B + b] - lr) / lr;
      s2 += e * e;
      ++n2;
    }
  }
  r.rms_pixel_rel_error = n2 ? std::sqrt(s2 / n2) : 0;
  return r;
}

json base_scene(int spp, uint64_t seed, int max_depth) {
  return {{"format", "oralfluor-scene"},
          {"version", 1},
          {"integrator",
           {{"spp", spp}, {"seed", seed}, {"max_depth", max_depth}, {"rr_start_depth", 3},
            {"wavelengths", {{"min_nm", 380}, {"max_nm", 720}, {"step_nm", 5}}},
            {"output_bands", {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", 20}}}}}};
}

json tongue_like_reflectance() {
  return {{"type", "points"}, {"points", {{380, 0.20}, {450, 0.20}, {540, 0.16}, {580, 0.25}, {620, 0.50}, {720, 0.65}}}};
}

struct Rendered {
  Scene scene;
  RenderResult result;
  double seconds;
};

Rendered render_json(const json& j, const std::string& name) {
  Rendered r{load_scene(JsonFile::from(j, "bench:" + name)), {}, 0};
  auto t0 = std::chrono::steady_clock::now();
  RenderOptions o;
  o.progress = false;
  r.result = render(r.scene, o);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

BenchResult finish(BenchResult b, const Rendered& r, int spp) {
  b.spp = spp;
  b.seconds = r.seconds;
  b.camera_samples_per_second = r.result.stats.samples_per_second();
  return b;
}

// Case 1: Lambertian patch under a point LED with a cos^m profile, tilted so that on- and
// off-axis pixels see different angles: L = R E / pi, E = I0 S P(theta) cos(theta_i) / r^2.
BenchResult lambert_point_led(int spp, uint64_t seed) {
  json j = base_scene(spp, seed, 1);
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
  auto f = [&](const glm::dvec3& p, std::vector<double>& out) {
    glm::dvec3 to = p - led.position;
    double r2 = glm::dot(to, to);
    glm::dvec3 d = to / std::sqrt(r2);
    double cos_led = glm::dot(d, led.axis), cos_i = -d.z;
    double e = led.profile.eval(cos_led) * cos_i / r2;
    for (size_t b = 0; b < out.size(); ++b) out[b] = rs_bands[b] * e;
    return true;
  };
  Reference ref = plane_reference(sc, f, nullptr);
  // Pixel where the LED axis meets the patch, for an on-axis region.
  glm::dvec3 a = led.axis;
  glm::dvec3 hit = led.position + (-led.position.z / a.z) * a;
  const auto& c = sc.camera;
  double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0);
  int px = int((hit.x / (c.position.z * th) + 1) * 0.5 * c.width), py = int((1 - hit.y / (c.position.z * th)) * 0.5 * c.height);
  auto b = compare("lambert_point_led", sc, r.result.image, ref,
                   {{"on-axis", {px - 4, py - 4, px + 4, py + 4}}, {"whole", {0, 0, c.width, c.height}}});
  return finish(b, r, spp);
}

// Case 4: a Lambertian disk LED (m = 1, radius a) above a patch; irradiance of a point of a
// parallel plane at distance h and radial offset rho: E = pi L / 2 (1 - (h^2 + rho^2 - a^2) /
// sqrt((h^2 + rho^2 + a^2)^2 - 4 rho^2 a^2)); on the axis this is E = pi L a^2 / (h^2 + a^2).
BenchResult disk_led(int spp, uint64_t seed) {
  json j = base_scene(spp, seed, 1);
  const double h = 0.03, a = 0.015;
  j["camera"] = {{"position", {0.12, 0, 0.16}}, {"look_at", {0, 0, 0}}, {"up", {0, 0, 1}}, {"fov_deg", 20}, {"resolution", {96, 96}}};
  j["materials"] = {{"patch", {{"type", "lambertian"}, {"reflectance", 0.6}}}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.5, 0, 0}}, {"v", {0, 0.5, 0}}, {"material", "patch"}}};
  j["lights"] = {{{"type", "led"}, {"spd", {{"type", "gaussian"}, {"peak_nm", 560}, {"fwhm_nm", 200}}}, {"radiant_intensity_W_sr", 0.3},
                  {"profile", {{"cos_power", 1}}}, {"radius_m", a}, {"position", {0, 0, h}}, {"axis", {0, 0, -1}}}};
  Rendered r = render_json(j, "disk_led");
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  std::vector<double> Lr(sc.grid().size());
  for (size_t i = 0; i < Lr.size(); ++i) Lr[i] = sc.materials[0].reflectance[i] * led.spectral_intensity[i] / (kPi * a * a) / kPi;
  auto lb = to_bands(sc, Lr);  // R L_led / pi per band; times pi/2 (...) below
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
  // The on-axis point seen by the camera.
  const auto& c = sc.camera;
  int cx = c.width / 2, cy = c.height / 2;
  auto b = compare("disk_led", sc, r.result.image, ref, {{"on-axis", {cx - 3, cy - 3, cx + 3, cy + 3}}, {"whole", {0, 0, c.width, c.height}}});
  return finish(b, r, spp);
}

// Case 3: inside a closed Lambertian sphere of reflectance R that emits Le uniformly, the
// radiance is L = Le / (1 - R) everywhere (multiple bounces, energy conservation).
BenchResult closed_sphere(int spp, uint64_t seed) {
  json j = base_scene(spp, seed, 100000);
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
  return finish(b, r, spp);
}

}  // namespace

nlohmann::json BenchResult::to_json() const {
  json regs = json::array();
  for (auto& r : regions) regs.push_back({{"name", r.name}, {"rel_error", r.rel_error}, {"max_band_error", r.max_band_error}, {"pixels", r.pixels}});
  return {{"case", name}, {"spp", spp}, {"mean_rel_error", mean_rel_error}, {"max_rel_error", max_rel_error},
          {"rms_pixel_rel_error", rms_pixel_rel_error}, {"seconds", seconds},
          {"camera_samples_per_second", camera_samples_per_second}, {"regions", regs}};
}

std::vector<BenchCaseInfo> bench_cases() {
  return {
      {"lambert_point_led", "Lambertian patch under a tilted point LED with a cos^m profile (30 deg half-angle): L = R I0 S P(theta) cos(theta_i) / (pi r^2), on- and off-axis pixels", 256},
      {"disk_led", "Lambertian disk LED (radius 15 mm, 30 mm above a patch): E = pi L a^2 / (h^2 + a^2) on axis and the parallel-plane disk formula off axis; checks MIS", 256},
      {"closed_sphere", "camera inside a closed emitting Lambertian sphere: L = Le / (1 - R) per wavelength (multiple bounces, Russian roulette)", 256},
  };
}

BenchResult run_bench_case(const std::string& name, int spp, uint64_t seed) {
  if (name == "lambert_point_led") return lambert_point_led(spp, seed);
  if (name == "disk_led") return disk_led(spp, seed);
  if (name == "closed_sphere") return closed_sphere(spp, seed);
  std::string names;
  for (auto& c : bench_cases()) names += (names.empty() ? "" : ", ") + c.name;
  throw InputError("", "case \"" + name + "\"", "unknown bench case (have: " + names + ")");
}

}  // namespace ofl
