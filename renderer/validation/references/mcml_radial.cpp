// Lateral transport against MCML's radial profiles (mcml.h: mcml_radial_case). The slab's lateral
// profiles are filled by the same code the renderer's spatial transport uses
// (renderer/render/spatial/stack_profiles.h), launched at normal incidence, in independent batches
// whose spread gives the standard errors; MCML's diffuse reflectance per ring is summed into the
// reflectance within each ring edge.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "renderer/validation/references/mcml.h"
#include "renderer/render/spatial/stack_profiles.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

namespace {

constexpr int kBatches = 8;

// MCML's diffuse reflectance within radius edge(i) = (i + 1) dr, mm, for every ring but the
// overflow one.
std::vector<std::pair<double, double>> mcml_cumulative(const McmlOutput& m) {
  std::vector<std::pair<double, double>> c;
  double acc = 0;
  for (size_t i = 0; i + 1 < m.rd_r.size(); ++i) {
    const double r0 = i * m.dr_cm, r1 = (i + 1) * m.dr_cm;
    acc += m.rd_r[i] * kPi * (r1 * r1 - r0 * r0);
    c.emplace_back(10.0 * r1, acc);
  }
  return c;
}

// The radius (mm) within which `fraction` of the total lies, from a cumulative curve (linear in r
// between its points); negative when it is never reached.
double radius_holding(const std::vector<std::pair<double, double>>& c, double total, double fraction) {
  double r_prev = 0, c_prev = 0;
  for (const auto& [r, v] : c) {
    if (v >= fraction * total) return r_prev + (fraction * total - c_prev) / std::max(v - c_prev, 1e-300) * (r - r_prev);
    r_prev = r;
    c_prev = v;
  }
  return -1;
}

struct Stat {
  double sum = 0, sum2 = 0;
  int n = 0;
  void add(double v) {
    sum += v;
    sum2 += v * v;
    ++n;
  }
  double mean() const { return n ? sum / n : 0.0; }
  double se() const { return n > 1 ? std::sqrt(std::max(0.0, (sum2 / n - mean() * mean()) / (n - 1))) : 0.0; }
};

}  // namespace

RadialSlabResult simulate_slab_radial(const McmlInput& in, long long photons, uint64_t seed, const std::vector<double>& radii_mm) {
  RadialSlabResult out;
  LayerStack stack = mcml_stack(in);
  StackTables st = build_stack_tables(stack, {}, {}, false);
  MaterialTables mt;
  std::vector<Stat> cum(radii_mm.size());
  Stat rd, r50, r90;
  for (int b = 0; b < kBatches; ++b) {
    StackProfileOptions o;
    o.cosines = {1.0};
    o.photons = int(std::max<long long>(1, photons / kBatches));
    o.seed = seed * 1000003ULL + uint64_t(b);
    o.clear_exits = false;
    auto p = build_stack_profiles(st, mt, 1, o);
    const double total = p->rd[0], inside = total * p->kept[0];
    std::vector<std::pair<double, double>> curve;
    for (size_t i = 0; i < radii_mm.size(); ++i) {
      const double v = inside * radial::cumulative(p->elastic_rings, p->elastic_cdf_at(0, 0), p->elastic_mass_at(0, 0), radii_mm[i]);
      cum[i].add(v);
      curve.emplace_back(radii_mm[i], v);
    }
    rd.add(total);
    r50.add(radius_holding(curve, total, 0.5));
    r90.add(radius_holding(curve, total, 0.9));
    out.walks += p->walks;
    out.seconds += p->build_seconds;
  }
  out.radii_mm = radii_mm;
  for (const Stat& s : cum) {
    out.cumulative.push_back(s.mean());
    out.cumulative_se.push_back(s.se());
  }
  out.rd = rd.mean();
  out.rd_se = rd.se();
  out.r50_mm = r50.mean();
  out.r50_se = r50.se();
  out.r90_mm = r90.mean();
  out.r90_se = r90.se();
  return out;
}

std::vector<BenchCheck> compare_radial_with_mcml(const RadialSlabResult& o, const McmlOutput& m) {
  const auto ref = mcml_cumulative(m);
  const double nm = m.photons > 0 ? double(m.photons) : 1e6;
  // MCML's standard error of a reflected fraction F of its photon packets: sqrt(F (1 - F) / N).
  auto mcml_se = [nm](double f) { return std::sqrt(std::max(f * (1 - f), 0.0) / nm); };
  std::vector<BenchCheck> c;
  c.push_back({"diffuse reflectance Rd (all radii)", o.rd, m.rd, mc_tolerance(0.01, m.rd, std::hypot(o.rd_se, mcml_se(m.rd)))});
  // The worst ring edge, as a ratio to its tolerance: 1 % of Rd, or 3 combined standard errors.
  double worst = -1;
  BenchCheck w;
  for (size_t i = 0; i < ref.size() && i < o.cumulative.size(); ++i) {
    const double tol = mc_tolerance(0.01, m.rd, std::hypot(o.cumulative_se[i], mcml_se(ref[i].second)));
    const double ratio = std::abs(o.cumulative[i] - ref[i].second) / tol;
    if (ratio > worst) {
      worst = ratio;
      char q[120];
      std::snprintf(q, sizeof q, "reflectance within r, worst ring edge (r = %.3f mm of %zu)", ref[i].first, ref.size());
      w = {q, o.cumulative[i], ref[i].second, tol};
    }
  }
  if (worst >= 0) c.push_back(w);
  for (double f : {0.5, 0.9}) {
    const double rm = radius_holding(ref, m.rd, f);
    if (rm <= 0) continue;
    const double ours = f == 0.5 ? o.r50_mm : o.r90_mm, se = f == 0.5 ? o.r50_se : o.r90_se;
    c.push_back({f == 0.5 ? "r50 (mm)" : "r90 (mm)", ours, rm, mc_tolerance(0.02, rm, se)});
  }
  return c;
}

CheckCaseResult mcml_radial_case(const McmlInput& in, const McmlOutput& ref, long long photons, uint64_t seed) {
  std::vector<double> radii;
  for (const auto& [r, v] : mcml_cumulative(ref)) radii.push_back(r);
  RadialSlabResult o = simulate_slab_radial(in, photons, seed, radii);
  CheckCaseResult r;
  r.name = "mcml_radial_" + in.name;
  r.samples = photons;
  r.seconds = o.seconds;
  r.checks = compare_radial_with_mcml(o, ref);
  r.extra["oralfluor"] = {{"Rd", o.rd}, {"Rd_se", o.rd_se}, {"r50_mm", o.r50_mm}, {"r90_mm", o.r90_mm},
                          {"radii_mm", o.radii_mm}, {"cumulative", o.cumulative}, {"cumulative_se", o.cumulative_se}};
  std::vector<double> mc;
  for (const auto& [rr, v] : mcml_cumulative(ref)) mc.push_back(v);
  r.extra["mcml"] = {{"Rd", ref.rd}, {"photons", ref.photons}, {"cumulative", mc}};
  return r;
}

std::filesystem::path mcml_radial_case_dir() { return std::filesystem::path(OFL_SOURCE_DIR) / "benchmarks" / "mcml_radial"; }

}  // namespace ofl
