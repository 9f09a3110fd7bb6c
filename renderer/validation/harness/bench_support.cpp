#include "renderer/validation/harness/bench_support.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl::bench {

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
                    const std::vector<Region>& extra_regions) {
  int W = img.width, H = img.height, B = img.bands();
  std::vector<Region> regions;
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

json base_scene(const BenchOptions& o, int max_depth, double gmin, double gmax, double band_step) {
  json j = {{"format", "oralfluor-scene"},
          {"version", 1},
          {"integrator",
           {{"spp", o.spp}, {"seed", o.seed}, {"max_depth", max_depth},
            {"direct_excitation", o.sampled_excitation ? "sampled" : "deterministic"},
            {"wavelengths", {{"min_nm", gmin}, {"max_nm", gmax}, {"step_nm", 5}}},
            {"output_bands", {{"min_nm", 400}, {"max_nm", 700}, {"step_nm", band_step}}}}}};
  if (!o.importance_camera.empty()) j["integrator"]["importance_camera"] = o.importance_camera;
  if (!o.light_selection.empty()) j["integrator"]["light_selection"] = o.light_selection;
  return j;
}

Rendered render_json(const json& j, const std::string& name) {
  Rendered r{load_scene(JsonFile::from(j, "bench:" + name)), {}, 0};
  auto t0 = std::chrono::steady_clock::now();
  RenderOptions o;
  o.progress = false;
  r.result = render(r.scene, o);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

BenchResult finish(BenchResult b, const Rendered& r, const BenchOptions& o) {
  b.spp = o.spp;
  b.seconds = r.seconds;
  b.camera_samples_per_second = r.result.stats.samples_per_second();
  return b;
}


PlaneRadiance point_led_on_plane(const LedLight& led, std::vector<double> per_unit) {
  return [&led, per_unit](const glm::dvec3& p, std::vector<double>& out) {
    glm::dvec3 to = p - led.position;
    double r2 = glm::dot(to, to);
    glm::dvec3 d = to / std::sqrt(r2);
    double e = led.profile.eval(glm::dot(d, led.axis)) * (-d.z) / r2;
    for (size_t b = 0; b < out.size(); ++b) out[b] = per_unit[b] * e;
    return true;
  };
}

Reference uniform_reference(const Scene& sc, const std::vector<double>& bands) {
  Reference ref;
  size_t n = size_t(sc.camera.width) * sc.camera.height;
  ref.valid.assign(n, 1);
  for (size_t p = 0; p < n; ++p) ref.L.insert(ref.L.end(), bands.begin(), bands.end());
  return ref;
}

std::array<int, 2> pixel_of(const CameraSpec& c, const glm::dvec3& p) {
  glm::dvec3 f = glm::normalize(c.look_at - c.position);
  glm::dvec3 r = glm::normalize(glm::cross(f, c.up));
  glm::dvec3 u = glm::cross(r, f);
  glm::dvec3 d = p - c.position;
  double z = glm::dot(d, f);
  double th = std::tan(0.5 * c.vfov_deg * kPi / 180.0), tw = th * double(c.width) / c.height;
  double sx = glm::dot(d, r) / z / tw, sy = glm::dot(d, u) / z / th;
  return {int((sx + 1) * 0.5 * c.width), int((1 - sy) * 0.5 * c.height)};
}

Scene stack_bench_scene(const nlohmann::json& material, const nlohmann::json& spd, double min_nm, double max_nm) {
  using nlohmann::json;
  json j = {{"format", "oralfluor-scene"}, {"version", 1},
            {"integrator", {{"wavelengths", {{"min_nm", min_nm}, {"max_nm", max_nm}, {"step_nm", 5}}},
                            {"output_bands", {{"min_nm", min_nm + 10}, {"max_nm", max_nm - 10}, {"step_nm", 10}}}}},
            {"camera", {{"position", {0, 0, 1}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 10}, {"resolution", {4, 4}}}},
            {"materials", {{"m", material}}},
            {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {1, 0, 0}}, {"v", {0, 1, 0}}, {"material", "m"}}}},
            {"lights", {{{"spd", spd}, {"radiant_intensity_W_sr", 1.0}, {"position", {0, 0, 10}}, {"target", {0, 0, 0}}}}}};
  return load_scene(JsonFile::from(j, "stack_bench.json"));
}

}  // namespace ofl::bench
