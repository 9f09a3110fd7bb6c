// Closed-form checks of the layered-tissue BSDF (docs/layered-tissue.md, "Validation"), evaluated through the
// same call the path tracer makes at a layered vertex (layered_scatter):
//   layered_fluorescent_escape  a non-scattering fluorescent layer under a collimated beam: the
//     excitation decays as exp(-a z / mu_i), isotropic emission leaves through the top with
//     exp(-b z / mu_o); radiance L(mu_o) = sum_ex sigma(em <- ex) E(ex) / (4 pi mu_i mu_o)
//     * (1 - exp(-d (a / mu_i + b / mu_o))) / (a / mu_i + b / mu_o) and exitance
//     M = sum_ex sigma E / mu_i * integral_0^d exp(-a z / mu_i) E2(b z) / 2 dz (exponential integral);
//   layered_scattering_fluorescence  a scattering fluorescent half-space (n = 1.37, smooth top)
//     under a normal beam: the camera-side exitance (next-event estimation with direct and
//     scattered excitation) against an analog forward Monte Carlo of excitation and emission
//     photons written here, independent of the walk;
//   layered_furnace  a non-absorbing stack with index steps over a white base returns everything
//     (albedo 1 for every incidence), and a non-absorbing open slab reflects plus transmits 1;
//   layered_coated_lambertian  a clear film of index n over a Lambertian base:
//     f = (1 - F(theta_i)) (1 - F(theta_o)) rho / (pi n^2 (1 - rho r_i)), r_i = 1 - (1 - F_avg) / n^2.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

#include "renderer/validation/harness/bench_check.h"
#include "renderer/validation/harness/bench_support.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/validation/references/mcml.h"
#include "renderer/validation/cases/spatial_cases.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/integrator/layered_bsdf.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

bool BenchCheck::pass() const { return std::isfinite(value) && std::abs(value - reference) <= tolerance; }

bool CheckCaseResult::pass() const {
  for (const auto& c : checks)
    if (!c.pass()) return false;
  return true;
}

nlohmann::json CheckCaseResult::to_json() const {
  nlohmann::json j = {{"case", name}, {"samples", samples}, {"seconds", seconds}, {"pass", pass()}};
  nlohmann::json cs = nlohmann::json::array();
  for (const auto& c : checks)
    cs.push_back({{"quantity", c.quantity}, {"value", c.value}, {"reference", c.reference}, {"tolerance", c.tolerance},
                  {"pass", c.pass()}});
  j["checks"] = cs;
  j["extra"] = extra;
  return j;
}

namespace {

using nlohmann::json;

// A one-material scene around `material` with a distant LED of spectrum `spd`, so that the
// renderer's own tables (stack, base, LED photon shape) are built exactly as for a render.
struct StackBench {
  Scene scene;
  std::unique_ptr<RenderTables> tables_;
  const RenderTables& tables() const { return *tables_; }
  const MaterialTables& mt() const { return tables_->materials[0]; }
  const std::vector<float>& shape() const { return tables_->light_shape[0]; }
  int n() const { return tables_->n; }
};


std::unique_ptr<StackBench> make_bench(const json& material, const json& spd, double min_nm = 350, double max_nm = 750) {
  auto b = std::make_unique<StackBench>();
  json m = material;  // these cases check the walk itself
  if (!m.contains("transport")) m["transport"] = "walk";
  b->scene = bench::stack_bench_scene(m, spd, min_nm, max_nm);
  b->tables_ = std::make_unique<RenderTables>(b->scene);
  return b;
}

// Mean and standard error of the eight lanes' next-event radiance over `samples` evaluations of the
// stack's BSDF, the viewing and light directions from dirs(u1, u2, u3, u4) -> {wo, wi} (collimated
// light of unit irradiance per unit shape; the caller's cosine factors are its own).
struct LaneStats {
  double mean[kLanes] = {}, se[kLanes] = {};
};

template <class Dirs>
LaneStats nee_estimate(const StackBench& b, const int (&bins)[kLanes], long long samples, uint64_t seed, Dirs dirs) {
  LightSample ls;
  ls.valid = true;
  ls.group = 0;
  ls.g = 1.0;
  double s1[kLanes] = {}, s2[kLanes] = {};
  const StackPointFactors fac;
  for (long long i = 0; i < samples; ++i) {
    Rng rng(seed, Rng::stream_for(0x4C415945ULL, uint64_t(i)));
    auto [wo, wi] = dirs(rng.next_double(), rng.next_double(), rng.next_double(), rng.next_double());
    ls.wi = wi;
    PathLanes p;
    for (int k = 0; k < kLanes; ++k) {
      p.film[k] = p.wl[k] = bins[k];
      p.beta[k] = 1;
      p.L[k] = p.Lf[k] = 0;
      p.fl[k] = p.rerad_prev[k] = false;
    }
    layered_scatter(b.mt(), fac, wo, ls, b.tables().light_shape, b.n(), p, rng);
    for (int k = 0; k < kLanes; ++k) {
      s1[k] += p.L[k];
      s2[k] += double(p.L[k]) * p.L[k];
    }
  }
  LaneStats st;
  for (int k = 0; k < kLanes; ++k) {
    st.mean[k] = s1[k] / samples;
    st.se[k] = std::sqrt(std::max(0.0, s2[k] / samples - st.mean[k] * st.mean[k]) / samples);
  }
  return st;
}

using Dirs = std::pair<glm::dvec3, glm::dvec3>;

glm::dvec3 dir_at(double theta_deg) {
  double t = theta_deg * kPi / 180.0;
  return {std::sin(t), 0.0, std::cos(t)};
}

// E_n(x) for n = 1, 2 (x > 0): E1 = -Ei(-x), E2 = exp(-x) - x E1.
double expint_e2(double x) {
  if (x <= 0) return 1.0;
  double e1 = -std::expint(-x);
  return std::exp(-x) - x * e1;
}

// The fluorescent layer: a synthetic fluorophore whose emission it does not re-absorb
// (benchmarks/data/synthetic_fluorophore.json) at 2 /mm at its peak, QY 0.6, over a background
// absorber; index 1 everywhere.
json fluorescent_layer(double thickness_mm) {
  std::string fl = std::string(OFL_SOURCE_DIR) + "/benchmarks/data/synthetic_fluorophore.json";
  json layer = {{"name", "fluorescent"}, {"ior", 1.0},
                {"absorption", {{"baseline_per_mm", {{"type", "points"}, {"points", {{300, 0.8}, {900, 0.2}}}}}}},
                {"fluorophores", {{{"fluorophore", fl}, {"mua_per_mm", 2.0}, {"quantum_yield", 0.6}}}}};
  json m = {{"type", "layered_tissue"}, {"layers", {layer}}};
  if (thickness_mm > 0) {
    m["layers"][0]["thickness_mm"] = thickness_mm;
    m["bottom"] = {{"type", "open"}, {"ior", 1.0}};
  }
  return m;
}

CheckCaseResult fluorescent_escape(long long samples, uint64_t seed) {
  CheckCaseResult r;
  r.name = "layered_fluorescent_escape";
  r.samples = samples;
  const json led = {{"type", "gaussian"}, {"peak_nm", 425}, {"fwhm_nm", 20}};
  const int bins_nm[kLanes] = {480, 500, 520, 540, 560, 580, 610, 650};
  for (double d : {0.0, 0.3}) {
    auto b = make_bench(fluorescent_layer(d), led);
    const Scene& sc = b->scene;
    const TissueLayer& L = sc.materials[0].stack.layers[0];
    const LayerFluorophore& f = L.fluorophores[0];
    const GridEem& eem = sc.eems[f.eem];
    const double step = sc.grid().step_nm;
    auto albedo = eem.photon_albedo();
    const double a_peak = *std::max_element(albedo.begin(), albedo.end());
    auto mut = [&](int i) { return L.mua[i] + L.mus[i] + f.mua_peak_per_mm * albedo[i] / a_peak; };
    int bins[kLanes];
    for (int k = 0; k < kLanes; ++k) bins[k] = sc.grid().index_of(bins_nm[k]);
    const double depth = d > 0 ? d : std::numeric_limits<double>::infinity();
    // Closed forms, independent of the walk: photon radiance per unit irradiance per unit shape.
    auto radiance = [&](int em, double mu_i, double mu_o) {
      double sum = 0;
      for (int ex = 0; ex < em; ++ex) {
        double sigma = f.mua_peak_per_mm * f.quantum_yield * eem.at(em, ex) / a_peak * step;
        double k = mut(ex) / mu_i + mut(em) / mu_o;
        double slab = std::isfinite(depth) ? (1.0 - std::exp(-depth * k)) / k : 1.0 / k;
        sum += sigma * b->shape()[ex] / (4.0 * kPi * mu_i * mu_o) * slab;
      }
      return sum;
    };
    auto exitance = [&](int em) {  // mu_i = 1
      double sum = 0;
      for (int ex = 0; ex < em; ++ex) {
        double sigma = f.mua_peak_per_mm * f.quantum_yield * eem.at(em, ex) / a_peak * step;
        double a = mut(ex), bb = mut(em), integral;
        if (!std::isfinite(depth)) {
          integral = 0.5 / a * (1.0 - bb / a * std::log(1.0 + a / bb));
        } else {  // midpoint rule on 4000 steps; E2 is smooth away from z = 0, where it is bounded
          const int m = 4000;
          integral = 0;
          for (int i = 0; i < m; ++i) {
            double z = (i + 0.5) * depth / m;
            integral += std::exp(-a * z) * 0.5 * expint_e2(bb * z) * depth / m;
          }
        }
        sum += sigma * b->shape()[ex] * integral;
      }
      return sum;
    };
    std::string tag = d > 0 ? " (0.3 mm slab)" : " (semi-infinite)";
    for (double theta_i : {0.0, 40.0})
      for (double theta_o : {0.0, 60.0}) {
        LaneStats s = nee_estimate(*b, bins, samples, seed, [&](double, double, double, double) {
          return Dirs{dir_at(-theta_o), dir_at(theta_i)};
        });
        for (int k : {1, 3, 6}) {
          double ref = radiance(bins[k], std::cos(theta_i * kPi / 180), std::cos(theta_o * kPi / 180));
          char q[160];
          std::snprintf(q, sizeof q, "radiance at %d nm, in %g deg, out %g deg%s", bins_nm[k], theta_i, theta_o, tag.c_str());
          r.checks.push_back({q, s.mean[k], ref, mc_tolerance(0.01, ref, s.se[k])});
        }
      }
    LaneStats m = nee_estimate(*b, bins, samples, seed + 1, [](double u1, double u2, double, double) {
      return Dirs{sample_cosine_hemisphere(u1, u2), glm::dvec3(0, 0, 1)};
    });
    for (int k = 0; k < kLanes; ++k) {
      double ref = exitance(bins[k]);
      char q[160];
      std::snprintf(q, sizeof q, "exitance at %d nm (E2 escape)%s", bins_nm[k], tag.c_str());
      r.checks.push_back({q, kPi * m.mean[k], ref, mc_tolerance(0.01, ref, kPi * m.se[k])});
    }
  }
  return r;
}

// Analog forward photons through one semi-infinite layer (smooth top, index n over vacuum, normal
// incidence): excitation photons drawn from the LED's photon shape scatter (HG), are absorbed, or
// are absorbed by the fluorophores and re-emitted isotropically at a wavelength drawn from the
// emission column; tallies the fluorescence photons that leave through the top per bin.
std::vector<double> forward_fluorescence(const StackBench& b, long long photons, uint64_t seed) {
  const StackLayerTables& L = b.mt().stack.layers.at(0);
  const double n_rel = 1.0 / L.ior;
  const int n = b.n();
  const auto& shape = b.shape();
  std::vector<double> cdf(n + 1, 0.0), tally(n, 0.0);
  for (int i = 0; i < n; ++i) cdf[i + 1] = cdf[i] + shape[i];
  auto fl_absorb = [&](int w) {
    double a = 0;
    for (const auto& f : L.fluors) a += f.absorb[w];
    return a;
  };
  for (long long i = 0; i < photons; ++i) {
    Rng rng(seed, Rng::stream_for(0x46574430ULL, uint64_t(i)));
    int w = int(std::upper_bound(cdf.begin(), cdf.end(), rng.next_double() * cdf[n]) - cdf.begin()) - 1;
    w = std::clamp(w, 0, n - 1);
    if (rng.next_double() < fresnel_dielectric(1.0, L.ior)) continue;  // specular reflection
    double depth = 0;
    glm::dvec3 d(0, 0, -1);
    bool fluorescent = false;
    for (int step = 0; step < 100000; ++step) {
      const double fa = fl_absorb(w), mut = L.mua[w] + L.mus[w] + fa;
      const double t = -std::log(1.0 - rng.next_double()) / mut;
      if (d.z > 0 && depth - t * d.z <= 0) {  // reaches the top: leaves or reflects back
        if (rng.next_double() < fresnel_dielectric(d.z, n_rel)) {
          depth = 0;
          d.z = -d.z;
          continue;
        }
        if (fluorescent) tally[w] += 1.0;
        break;
      }
      depth -= t * d.z;
      double u = rng.next_double() * mut;
      if (u < L.mus[w]) {
        d = sample_hg(L.g, d, rng.next_double(), rng.next_double());
        continue;
      }
      if (u >= L.mus[w] + fa) break;  // absorbed by a chromophore
      // Absorbed by a fluorophore: re-emitted at em with probability emit(em <- w) / fa.
      double v = rng.next_double() * fa;
      int em = -1;
      for (const auto& f : L.fluors)
        for (int e = w + 1; e < n && em < 0; ++e) {
          v -= f.emit[size_t(e) * n + w];
          if (v < 0) em = e;
        }
      if (em < 0) break;  // not re-emitted (quantum yield)
      w = em;
      fluorescent = true;
      d = sample_uniform_sphere(rng.next_double(), rng.next_double());
    }
  }
  for (int i = 0; i < n; ++i) tally[i] *= cdf[n] / double(photons);
  return tally;
}

CheckCaseResult scattering_fluorescence(long long samples, uint64_t seed) {
  CheckCaseResult r;
  r.name = "layered_scattering_fluorescence";
  r.samples = samples;
  json m = fluorescent_layer(0);
  m["layers"][0]["ior"] = 1.37;
  m["layers"][0]["scattering"] = {{"g", 0.8}, {"mus_per_mm", 10.0}};
  auto b = make_bench(m, {{"type", "gaussian"}, {"peak_nm", 425}, {"fwhm_nm", 20}});
  const int bins_nm[kLanes] = {490, 505, 520, 535, 550, 570, 600, 630};
  int bins[kLanes];
  for (int k = 0; k < kLanes; ++k) bins[k] = b->scene.grid().index_of(bins_nm[k]);
  LaneStats cam = nee_estimate(*b, bins, samples, seed, [](double u1, double u2, double, double) {
    return Dirs{sample_cosine_hemisphere(u1, u2), glm::dvec3(0, 0, 1)};
  });
  const long long photons = 40 * samples;
  auto fwd = forward_fluorescence(*b, photons, seed + 7);
  const double total_shape = std::accumulate(b->shape().begin(), b->shape().end(), 0.0);
  for (int k = 0; k < kLanes; ++k) {
    double ref = fwd[bins[k]];
    // Poisson standard error of the forward tally, in the same units.
    double se_fwd = std::sqrt(ref * total_shape / double(photons));
    double se = std::hypot(kPi * cam.se[k], se_fwd);
    char q[160];
    std::snprintf(q, sizeof q, "exitance at %d nm, camera side vs forward photons", bins_nm[k]);
    r.checks.push_back({q, kPi * cam.mean[k], ref, mc_tolerance(0.0, ref, se)});
  }
  return r;
}

// Mean continuation weight (albedo) for viewing direction wo, over `samples` walks.
std::pair<double, double> albedo(const StackBench& b, const glm::dvec3& wo, long long samples, uint64_t seed, int bin) {
  double s1 = 0, s2 = 0;
  const StackPointFactors fac;
  LightSample none;
  for (long long i = 0; i < samples; ++i) {
    Rng rng(seed, Rng::stream_for(0x46555252ULL, uint64_t(i)));
    PathLanes p;
    for (int k = 0; k < kLanes; ++k) {
      p.film[k] = p.wl[k] = bin;
      p.beta[k] = 1;
      p.L[k] = p.Lf[k] = 0;
      p.fl[k] = p.rerad_prev[k] = false;
    }
    LayeredScatter s = layered_scatter(b.mt(), fac, wo, none, b.tables().light_shape, b.n(), p, rng);
    double w = s.ok ? p.beta[0] : 0.0;
    s1 += w;
    s2 += w * w;
  }
  double mean = s1 / samples;
  return {mean, std::sqrt(std::max(0.0, s2 / samples - mean * mean) / samples)};
}

CheckCaseResult furnace(long long samples, uint64_t seed) {
  CheckCaseResult r;
  r.name = "layered_furnace";
  r.samples = samples;
  auto layer = [](const char* name, double d, double n, double mus, double g) {
    return json{{"name", name}, {"thickness_mm", d}, {"ior", n}, {"scattering", {{"g", g}, {"mus_per_mm", mus}}}};
  };
  json stack = {{"type", "layered_tissue"},
                {"layers", {layer("keratin", 0.03, 1.5, 20.0, 0.9), layer("epithelium", 0.2, 1.37, 5.0, 0.8),
                            layer("stroma", 0.5, 1.4, 10.0, 0.9)}},
                {"bottom", {{"type", "base"}, {"reflectance", 1.0}}}};
  for (bool rough : {false, true}) {
    json m = stack;
    if (rough) m["coating"] = {{"ior", 1.33}, {"roughness", 0.25}, {"thickness_mm", 0.01}};
    auto b = make_bench(m, 1.0);
    int bin = b->scene.grid().index_of(550);
    // Evaluation agrees with sampling: the albedo from next-event estimation over cosine-distributed
    // light directions, pi E[f], is also 1, less (smooth top) the mirror reflection F(35 deg), which
    // is a delta that next-event estimation cannot reach.
    {
      int bins[kLanes];
      std::fill(bins, bins + kLanes, bin);
      LaneStats e = nee_estimate(*b, bins, samples, seed + 7, [](double u1, double u2, double, double) {
        return Dirs{dir_at(35), sample_cosine_hemisphere(u1, u2)};
      });
      double mean = kPi * e.mean[0] / b->shape()[bin], se = kPi * e.se[0] / b->shape()[bin];
      double ref = rough ? 1.0 : 1.0 - fresnel_dielectric(std::cos(35 * kPi / 180), 1.5);
      r.checks.push_back({std::string("albedo by next-event estimation, ") + (rough ? "rough top" : "smooth top, less F") + ", 35 deg", mean,
                          ref, mc_tolerance(0.01, ref, se)});
    }
    for (double th : {0.0, 45.0, 75.0}) {
      auto [mean, se] = albedo(*b, dir_at(th), samples, seed, bin);
      char q[160];
      if (!rough) {
        std::snprintf(q, sizeof q, "albedo, smooth top, %g deg (everything that enters leaves)", th);
        r.checks.push_back({q, mean, 1.0, mc_tolerance(0.005, 1.0, se)});
      } else {
        std::snprintf(q, sizeof q, "albedo, rough wet top, %g deg (everything that enters leaves)", th);
        r.checks.push_back({q, mean, 1.0, mc_tolerance(0.005, 1.0, se)});
      }
    }
  }
  // An open non-absorbing slab with index mismatches: photons reflected plus transmitted = 1.
  McmlInput in;
  in.name = "furnace_slab";
  in.n_above = 1.0;
  in.n_below = 1.2;
  in.layers = {{1.5, 0.0, 60.0, 0.8, 0.02}, {1.37, 0.0, 150.0, 0.9, 0.05}};
  SlabResult s = simulate_slab(in, samples, seed);
  r.checks.push_back({"open slab: Rsp + Rd + Tt", s.rsp + s.rd + s.tt, 1.0, mc_tolerance(0.002, 1.0, std::hypot(s.rd_se, s.tt_se))});
  r.checks.push_back({"open slab: absorbed", s.a, 0.0, 1e-12});
  return r;
}

CheckCaseResult coated_lambertian(long long samples, uint64_t seed) {
  CheckCaseResult r;
  r.name = "layered_coated_lambertian";
  r.samples = samples;
  const double n = 1.33, rho = 0.5;
  json m = {{"type", "layered_tissue"},
            {"layers", {{{"name", "film"}, {"thickness_mm", 0.05}, {"ior", n}}}},
            {"bottom", {{"type", "base"}, {"reflectance", rho}}}};
  auto b = make_bench(m, 1.0);
  double favg = 0;
  for (int k = 0; k < 20000; ++k) {
    double mu = (k + 0.5) / 20000;
    favg += 2.0 * fresnel_dielectric(mu, n) * mu / 20000;
  }
  const double r_i = 1.0 - (1.0 - favg) / (n * n);
  int bins[kLanes];
  for (int k = 0; k < kLanes; ++k) bins[k] = b->scene.grid().index_of(450 + 25 * k);
  for (double ti : {0.0, 50.0})
    for (double to : {10.0, 70.0}) {
      double ref = (1 - fresnel_dielectric(std::cos(ti * kPi / 180), n)) * (1 - fresnel_dielectric(std::cos(to * kPi / 180), n)) *
                   rho / (kPi * n * n * (1 - rho * r_i));
      LaneStats s = nee_estimate(*b, bins, samples, seed, [&](double, double, double, double) { return Dirs{dir_at(-to), dir_at(ti)}; });
      double mean = 0, var = 0;
      for (int k = 0; k < kLanes; ++k) {
        mean += s.mean[k] / b->shape()[bins[k]] / kLanes;
        var += std::pow(s.se[k] / b->shape()[bins[k]] / kLanes, 2);
      }
      char q[160];
      std::snprintf(q, sizeof q, "BRDF, in %g deg, out %g deg", ti, to);
      r.checks.push_back({q, mean, ref, mc_tolerance(0.01, ref, std::sqrt(var))});
    }
  // Directional albedo: the specular reflection F plus the diffuse part (1 - F) rho (1 - F_avg) / (n^2 (1 - rho r_i)).
  auto [a, se] = albedo(*b, dir_at(30), samples, seed, bins[0]);
  double f30 = fresnel_dielectric(std::cos(30 * kPi / 180), n);
  double ref_a = f30 + (1 - f30) * rho * (1 - favg) / (n * n * (1 - rho * r_i));
  r.checks.push_back({"albedo at 30 deg (specular + diffuse)", a, ref_a, mc_tolerance(0.01, ref_a, se)});
  return r;
}

}  // namespace

// The fluorescent layer (0.3 mm, open below) rendered: a camera at 37 degrees, a point LED at the
// side; per pixel the closed-form radiance of layered_fluorescent_escape with that pixel's
// incidence and viewing angles and irradiance I0 S P(theta) cos(theta_i) / r^2.
// With transport "table" the same render reads the stack's tabulated response instead (the walk
// filled it at scene load; layered_fluorescent_slab_table).
static BenchResult fluorescent_slab_case(const BenchOptions& o, const std::string& name, const char* transport) {
  using namespace bench;
  json j = base_scene(o, 3, 350, 750);
  j["camera"] = {{"position", {0.15, 0, 0.2}}, {"look_at", {0, 0, 0}}, {"up", {0, 0, 1}}, {"fov_deg", 20}, {"resolution", {64, 64}}};
  json slab = fluorescent_layer(0.3);
  slab["transport"] = transport;
  // Without scattering a walk tallies one collision: many cheap walks keep the table's noise down.
  if (std::string(transport) == "table") slab["table_photons"] = 20000;
  j["materials"] = {{"slab", slab}};
  j["geometry"] = {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.4, 0, 0}}, {"v", {0, 0.4, 0}}, {"material", "slab"}}};
  j["lights"] = {{{"type", "led"}, {"spd", {{"type", "gaussian"}, {"peak_nm", 425}, {"fwhm_nm", 20}}}, {"radiant_intensity_W_sr", 0.5},
                  {"profile", {{"half_angle_deg", 40}}}, {"position", {-0.05, 0.02, 0.08}}, {"target", {0, 0, 0}}}};
  Rendered r = render_json(j, name);
  const Scene& sc = r.scene;
  const LedLight& led = sc.lights[0];
  const TissueLayer& L = sc.materials[0].stack.layers[0];
  const LayerFluorophore& f = L.fluorophores[0];
  const GridEem& eem = sc.eems[f.eem];
  const int n = sc.grid().size();
  const double step = sc.grid().step_nm, d = L.thickness_mm;
  auto albedo = eem.photon_albedo();
  const double a_peak = *std::max_element(albedo.begin(), albedo.end());
  auto mut = [&](int i) { return L.mua[i] + L.mus[i] + f.mua_peak_per_mm * albedo[i] / a_peak; };
  PlaneRadiance radiance = [&](const glm::dvec3& p, std::vector<double>& bands) {
    glm::dvec3 to_l = led.position - p, to_c = sc.camera.position - p;
    double rl = glm::length(to_l), mu_i = to_l.z / rl, mu_o = to_c.z / glm::length(to_c);
    double cos_l = -glm::dot(to_l / rl, led.axis);
    if (mu_i <= 0 || cos_l <= 0) return false;
    double geo = led.profile.eval(cos_l) * mu_i / (rl * rl);
    std::vector<double> w(n, 0.0);
    for (int em = 0; em < n; ++em) {
      double sum = 0;
      for (int ex = 0; ex < em; ++ex) {
        double sigma = f.mua_peak_per_mm * f.quantum_yield * eem.at(em, ex) / a_peak * step;
        double k = mut(ex) / mu_i + mut(em) / mu_o;
        sum += sigma * led.spectral_photons[ex] * geo / (4.0 * kPi * mu_i * mu_o) * (1.0 - std::exp(-d * k)) / k;
      }
      w[em] = sum * photon_energy_J(sc.grid().wavelength(em));
    }
    bands = to_bands(sc, w);
    return true;
  };
  Reference ref = plane_reference(sc, radiance, nullptr);
  auto b = compare(name, sc, r.result.image, ref, {{"whole", {0, 0, sc.camera.width, sc.camera.height}}});
  return finish(b, r, o);
}

BenchResult layered_fluorescent_slab(const BenchOptions& o) { return fluorescent_slab_case(o, "layered_fluorescent_slab", "walk"); }

BenchResult layered_fluorescent_slab_table(const BenchOptions& o) {
  return fluorescent_slab_case(o, "layered_fluorescent_slab_table", "table");
}

std::vector<CheckCaseInfo> check_cases() {
  std::vector<CheckCaseInfo> c = {
      {"layered_fluorescent_escape",
       "non-scattering fluorescent layer under a collimated 425 nm beam: radiance and exitance against exponential "
       "attenuation and exponential-integral escape, semi-infinite and 0.3 mm",
       20000},
      {"layered_scattering_fluorescence",
       "scattering fluorescent half-space (n = 1.37) under a normal 425 nm beam: camera-side exitance against analog "
       "forward photons",
       20000},
      {"layered_furnace", "non-absorbing three-layer stack with index steps over a white base: albedo 1; open slab: R + T = 1", 20000},
      {"layered_coated_lambertian", "clear film (n = 1.33) over a Lambertian base: the closed-form BRDF with internal reflections", 20000},
      {"spatial_fluorescence_pencil",
       "fluorescent two-layer slab under a normal 405 nm pencil beam: fluorescence exitance per ring from the spatial "
       "transport's tables against an independent forward photon Monte Carlo",
       4000000},
  };
  for (const char* transport : {"spatial", "volume"})
    for (const char* inside : {"dysplasia", "blood_spot"})
      for (double a : {0.25, 0.5, 1.0, 2.0, 5.0})
        for (bool fl : {false, true}) {
          char name[80];
          std::snprintf(name, sizeof name, "%s_lesion_%s_%gmm%s", transport, inside, a, fl ? "_fluorescence" : "");
          c.push_back({name,
                       std::string("a disc of ") + inside + " in lateral_tongue, lit uniformly: " +
                           (fl ? "fluorescence (405 nm)" : "reflectance") + " profile rendered with the \"" + transport +
                           "\" transport against a 3D forward Monte Carlo",
                       4000000});
        }
  for (const auto& name : mcml_case_names())
    c.push_back({"mcml_" + name, "MCML slab " + name + " (benchmarks/mcml): Rsp, Rd, Tt and absorption per layer", 1000000});
  for (const auto& name : mcml_case_names())
    c.push_back({"mcml_radial_" + name,
                 "MCML slab " + name + " (benchmarks/mcml_radial): the lateral profile the spatial transport uses, "
                 "reflectance within r, r50, r90",
                 4000000});
  return c;
}

bool is_check_case(const std::string& name) {
  for (const auto& c : check_cases())
    if (c.name == name) return true;
  return false;
}

CheckCaseResult run_check_case(const std::string& name, long long samples, uint64_t seed) {
  auto t0 = std::chrono::steady_clock::now();
  if (samples <= 0)
    for (const auto& c : check_cases())
      if (c.name == name) samples = c.default_samples;
  CheckCaseResult r;
  if (name == "layered_fluorescent_escape") r = fluorescent_escape(samples, seed);
  else if (name == "layered_furnace") r = furnace(samples, seed);
  else if (name == "layered_scattering_fluorescence") r = scattering_fluorescence(samples, seed);
  else if (name == "layered_coated_lambertian") r = coated_lambertian(samples, seed);
  else if (name == "spatial_fluorescence_pencil") r = spatial_fluorescence_pencil(samples, seed);
  else if (name.rfind("spatial_lesion_", 0) == 0 || name.rfind("volume_lesion_", 0) == 0) {
    // <spatial|volume>_lesion_<preset>_<a>mm[_fluorescence]
    const std::string transport = name.substr(0, name.find('_'));
    std::string rest = name.substr(transport.size() + 8);
    const bool fl = rest.size() > 13 && rest.compare(rest.size() - 13, 13, "_fluorescence") == 0;
    if (fl) rest.resize(rest.size() - 13);
    const size_t us = rest.rfind('_');
    const std::string preset = rest.substr(0, us);
    const double a = std::atof(rest.substr(us + 1).c_str());
    r = spatial_lesion_disc(preset, a, fl, samples, seed, transport);
  }
  else if (name.rfind("mcml_radial_", 0) == 0) {
    auto dir = mcml_radial_case_dir();
    std::string c = name.substr(12);
    auto runs = read_mci(dir / (c + ".mci"));
    McmlOutput ref = read_mco(dir / (c + ".mco"));
    r = mcml_radial_case(runs.at(0), ref, samples, seed);
  } else if (name.rfind("mcml_", 0) == 0) {
    auto dir = mcml_case_dir();
    std::string c = name.substr(5);
    auto runs = read_mci(dir / (c + ".mci"));
    McmlOutput ref = read_mco(dir / (c + ".mco"));
    r = mcml_case(runs.at(0), &ref, samples, seed);
  } else {
    throw InputError("", "case \"" + name + "\"", "unknown bench case (see oralfluor bench --list)");
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace ofl
