// How the spatial transport weighs reflected light that crosses regions (docs/layered-tissue.md,
// "Regions and lateral transport"), compared semi-analytically with other rules on the lesion discs'
// runs. For each disc of `--preset` in lateral_tongue, band and ring of the runs in --runs
// (`oralfluor bench spatial_lesion_<preset>_<a>mm --json`, written by benchmarks/lesion_results.sh),
// the two presets' elastic exit profiles at the camera's cosine (straight above) are integrated over
// the ring's exit points and every entry point under each rule, over the same integral for the
// disc-free tissue. A rule's prediction of the ring is the rendered contrast plus (its integral minus
// that of the rule the runs were rendered with); it is counted against the Monte Carlo's radiance
// along the normal as the bench case counts (within 2 % or 3 combined standard errors). One wavelength stands for each band (450,
// 560, 630 nm), the light's direction is taken as the normal's, and only reflected light is compared:
// a guide to which rule to render, not a substitute for rendering it.
//   usage: lesion_rules [--runs DIR (default benchmarks/lesion_runs, the runs kept in git)] [--preset blood_spot|dysplasia] [--rings] [--unraised-runs]
//   (--rings: every ring's Monte Carlo value, tolerance, rendered value and each rule's prediction;
//   --unraised-runs: the runs were rendered before the darker shares, with the "shares unraised" rule)
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/integrator/spatial_vertex.h"
#include "renderer/render/spatial/spatial_tables.h"
#include "renderer/scene/scene.h"
#include "renderer/spectral/spectra/units.h"
#include "renderer/validation/harness/bench_check.h"

using namespace ofl;

namespace {

// One preset's spatial tables, built from a flat scene of it (the profiles come from the cache).
struct Preset {
  Scene scene;
  std::unique_ptr<RenderTables> tables;
  const SpatialStack* stack = nullptr;
};

std::unique_ptr<Preset> load_preset(const std::string& name) {
  const nlohmann::json j = {
      {"format", "oralfluor-scene"}, {"version", 1}, {"integrator", {{"spp", 1}, {"max_depth", 2}}},
      {"camera", {{"position", {0, 0, 0.3}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}}, {"fov_deg", 3}, {"resolution", {4, 4}}}},
      {"materials", {{"t", {{"type", "layered_tissue"}, {"preset", name}, {"transport", "spatial"}}}}},
      {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {0.05, 0, 0}}, {"v", {0, 0.05, 0}}, {"material", "t"}}}},
      {"lights", {{{"spd", 1.0}, {"radiant_intensity_W_sr", 1}, {"position", {0, 0, 0.1}}, {"axis", {0, 0, -1}}}}}};
  auto p = std::make_unique<Preset>();
  p->scene = load_scene(JsonFile::from(j, name + ".json"));
  p->tables = std::make_unique<RenderTables>(p->scene, std::vector<double>{});
  for (const auto& m : p->tables->materials)
    if (m.stack.spatial) p->stack = m.stack.spatial.get();
  return p;
}

// Fraction of the segment p -> q (mm, in the plane) inside the disc of radius a about the origin.
double inside_fraction(double px, double py, double qx, double qy, double a) {
  const double dx = qx - px, dy = qy - py, A = dx * dx + dy * dy, B = 2 * (px * dx + py * dy), C = px * px + py * py - a * a;
  const double disc = B * B - 4 * A * C;
  if (disc <= 0 || A <= 0) return C < 0 ? 1.0 : 0.0;
  const double s = std::sqrt(disc);
  const double t0 = std::max((-B - s) / (2 * A), 0.0), t1 = std::min((-B + s) / (2 * A), 1.0);
  return t1 > t0 ? t1 - t0 : 0.0;
}

// The rules: the shipped one first (passages of L, the chord among them, chord_among_passages_mm,
// the darker material's share raised by darker_shares), the same shares unraised (shipped until
// 2026-11-28), then the chord's cap with other constants, the full chord (before 2026-11-28), the
// ends' geometric mean, the log ratio's end and chord parts, longer passages (diffuse light crosses
// a layer of thickness L along 2 L on average), and soft memberships: the ends and the chord's points
// count as the disc by an erfc of their distance to its edge, the darker material grown by sigma
// (x > 0 in mm, x < 0 in units of L) or both blurred; the darker material's share (the lower diffuse
// reflectance) raised to the power x (0: any share makes it all the darker material's); the power
// mean of exponent x of the two profiles at the path's length, weighted by the unraised shares;
// the bent chord: the path between the ends wanders sideways as a parabola whose middle lies a
// normal deviate of x r off the chord (x r: the lateral spread of a diffusing path's middle, about
// its depth r / (2 sqrt 2) in a half-space), the value the mean over the deviates of each bent
// path's product of powers (its darker share raised to gamma); or the bent paths' mean share taken
// first and the product of powers of that (the first-order perturbation of diffuse light by an
// absorber, where the log of the change is linear in the absorption along the light's paths).
enum class Kind { kShipped, kCap, kFullChord, kGeometricMean, kEndChordSplit, kPassage, kSoftDarker, kSoftBoth, kDarkerPower, kPowerMean, kBentChord, kBentShares };
struct Rule {
  const char* name;
  Kind kind;
  double x;  // kCap: the chord counts r / (1 + r / (x L)); kPassage: each passage is x L long (cap 2 L)
  double gamma = 1;  // kBentChord, kSoftDarker, kSoftBoth: the darker share's power (darker_shares)
};
const Rule kRules[] = {{"shipped (2 L cap, darker ^0.8)", Kind::kShipped, 0},
                       {"shares unraised", Kind::kDarkerPower, 1},  {"cap 0.5 L", Kind::kCap, 0.5},
                       {"cap 1 L", Kind::kCap, 1},                 {"cap 4 L", Kind::kCap, 4},
                       {"full chord", Kind::kFullChord, 0},        {"geometric mean of the ends", Kind::kGeometricMean, 0},
                       {"end and chord parts", Kind::kEndChordSplit, 0}, {"passages of 1.5 L", Kind::kPassage, 1.5},
                       {"passages of 2 L", Kind::kPassage, 2},
                       {"darker grown 0.05 mm", Kind::kSoftDarker, 0.05}, {"darker grown 0.1 mm", Kind::kSoftDarker, 0.1},
                       {"darker grown 0.15 mm", Kind::kSoftDarker, 0.15}, {"darker grown 0.5 L", Kind::kSoftDarker, -0.5},
                       {"both blurred 0.05 mm", Kind::kSoftBoth, 0.05}, {"both blurred 0.1 mm", Kind::kSoftBoth, 0.1},
                       {"darker share ^0.75", Kind::kDarkerPower, 0.75}, {"darker share ^0.85", Kind::kDarkerPower, 0.85}, {"darker share ^0.8", Kind::kDarkerPower, 0.8}, {"darker share ^0.7", Kind::kDarkerPower, 0.7}, {"darker share ^0.65", Kind::kDarkerPower, 0.65}, {"darker share ^0.5", Kind::kDarkerPower, 0.5},
                       {"darker share ^0.25", Kind::kDarkerPower, 0.25}, {"darker wins", Kind::kDarkerPower, 0},
                       {"power mean q = -0.5", Kind::kPowerMean, -0.5}, {"power mean q = -1", Kind::kPowerMean, -1},
                       {"power mean q = -2", Kind::kPowerMean, -2}, {"power mean q = -3", Kind::kPowerMean, -3},
                       {"bent 0.2 r", Kind::kBentChord, 0.2}, {"bent 0.35 r", Kind::kBentChord, 0.35},
                       {"bent 0.5 r", Kind::kBentChord, 0.5}, {"bent 0.35 r, darker ^0.8", Kind::kBentChord, 0.35, 0.8},
                       {"blurred 0.025 mm, ^0.8", Kind::kSoftBoth, 0.025, 0.8}, {"blurred 0.05 mm, ^0.8", Kind::kSoftBoth, 0.05, 0.8},
                       {"blurred 0.05 mm, ^0.9", Kind::kSoftBoth, 0.05, 0.9}, {"blurred 0.25 L, ^0.8", Kind::kSoftBoth, -0.25, 0.8},
                       {"blurred 0.25 L, ^0.9", Kind::kSoftBoth, -0.25, 0.9}, {"blurred 0.5 L, ^0.8", Kind::kSoftBoth, -0.5, 0.8},
                       {"bent shares 0.2 r", Kind::kBentShares, 0.2}, {"bent shares 0.35 r", Kind::kBentShares, 0.35},
                       {"bent shares 0.5 r", Kind::kBentShares, 0.5}, {"bent shares 0.2 r, ^0.8", Kind::kBentShares, 0.2, 0.8},
                       {"bent shares 0.35 r, ^0.8", Kind::kBentShares, 0.35, 0.8}, {"bent shares 0.35 r, ^0.9", Kind::kBentShares, 0.35, 0.9}};
constexpr int kNumRules = sizeof(kRules) / sizeof(kRules[0]);

// A rule tried and not kept (docs/layered-tissue.md, "Regions and lateral transport"): the log ratio
// of two materials' exit densities, y(r) = ln(P_b / P_a)(r), split by least squares over the rings
// (weights: the two profiles' mean mass) into a part per end in b and a part per mm of chord among
// the layers that differ, y = 2 e + g c(r) + rest; a path then takes the end part per end it has in
// b, the chord part for the chord it runs in b, and the rest by b's share (the shipped rule's).
struct EndChordSplit {
  double e = 0, g = 0;
};
EndChordSplit split_log_ratio(const float* dens_a, const float* dens_b, const RadialRings& rings, double L) {
  double s00 = 0, s01 = 0, s11 = 0, t0 = 0, t1 = 0;
  for (int j = 0; j < rings.rings; ++j) {
    if (!(dens_a[j] > 0 && dens_b[j] > 0)) continue;
    const double r = 0.5 * (rings.edge(j) + rings.edge(j + 1));
    const double w = 0.5 * (double(dens_a[j]) + dens_b[j]) * rings.area(j);
    const double x = chord_among_passages_mm(r, L), y = std::log(double(dens_b[j]) / dens_a[j]);
    s00 += 4 * w;
    s01 += 2 * w * x;
    s11 += w * x * x;
    t0 += 2 * w * y;
    t1 += w * x * y;
  }
  EndChordSplit sp;
  const double det = s00 * s11 - s01 * s01;
  if (!(std::abs(det) > 1e-12 * s00 * s11)) return sp;
  sp.e = (t0 * s11 - t1 * s01) / det;
  sp.g = (s00 * t1 - s01 * t0) / det;
  return sp;
}
// What material b adds to the log of the BSSRDF of the exit point's material a (y: their log ratio at
// the path's length, share: b's share by passage_share, ends_in_b: 0 or 1, chord_frac: the chord's
// fraction in b, along: the chord's length among the layers that differ).
double crossed_log_term(double y, double share, int ends_in_b, double chord_frac, const EndChordSplit& s, double along) {
  return share * y + s.e * (ends_in_b - 2.0 * share) + s.g * along * (chord_frac - share);
}

// The disc's soft membership of a point rho from the disc's centre (sigma: the margin; grow: the disc
// grows outward (1), shrinks inward (-1) or is blurred both ways (0)), and its mean along a segment.
double soft_member(double rho, double a, double sigma, int grow) {
  const double d = rho - a, k = 1 / (std::sqrt(2.0) * sigma);
  if (grow > 0) return d <= 0 ? 1.0 : 0.5 * std::erfc(d * k);
  if (grow < 0) return d >= 0 ? 0.0 : 1 - 0.5 * std::erfc(-d * k);
  return 0.5 * std::erfc(d * k);
}
double soft_fraction(double px, double py, double qx, double qy, double a, double sigma, int grow) {
  constexpr int kSteps = 16;
  double s = 0;
  for (int i = 0; i < kSteps; ++i) {
    const double t = (i + 0.5) / kSteps, x = px + t * (qx - px), y = py + t * (qy - py);
    s += soft_member(std::sqrt(x * x + y * y), a, sigma, grow);
  }
  return s / kSteps;
}

// Fraction of the path from p to q (mm, in the plane) inside the disc of radius a when its middle
// lies `bend` mm to the left of the chord, the offset growing as 4 t (1 - t) along it.
double bent_inside_fraction(double px, double py, double qx, double qy, double a, double bend) {
  constexpr int kSteps = 32;
  const double dx = qx - px, dy = qy - py, len = std::hypot(dx, dy);
  if (!(len > 0)) return px * px + py * py < a * a ? 1.0 : 0.0;
  const double nx = -dy / len, ny = dx / len;
  int in = 0;
  for (int i = 0; i < kSteps; ++i) {
    const double t = (i + 0.5) / kSteps, o = 4 * t * (1 - t) * bend;
    const double x = px + t * dx + o * nx, y = py + t * dy + o * ny;
    in += x * x + y * y < a * a;
  }
  return double(in) / kSteps;
}

// The rules' values for light entering at (xi, yi) and leaving at (d, 0), r apart, profiles p[0]
// (healthy) and p[1] (disc) at r.
// sp[m]: the split of ln(p[1 - m] / p[m]) (split_log_ratio, the ends' parts with half the log ratio of
// the diffuse reflectances, as the renderer's elastic_values counts the tables').
void rule_values(double d, double xi, double yi, double r, double a, double L, const double* p, const EndChordSplit* sp,
                 bool disc_darker, double* v) {
  const int mi = xi * xi + yi * yi < a * a ? 1 : 0, mo = d < a ? 1 : 0;
  const double f = inside_fraction(d, 0, xi, yi, a);
  auto mix = [&](double along, double passage) {  // the disc's share by the renderer's own arithmetic
    const double share = passage_share(f, mi + mo, 2, passage, along);
    return std::pow(p[1], share) * std::pow(p[0], 1 - share);
  };
  const double cap = chord_among_passages_mm(r, L);
  for (int k = 0; k < kNumRules; ++k) {
    const Rule& rule = kRules[k];
    switch (rule.kind) {
      case Kind::kCap: v[k] = mix(r / (1 + r / (rule.x * L)), L); break;
      case Kind::kFullChord: v[k] = mix(r, L); break;
      case Kind::kGeometricMean: v[k] = std::sqrt(p[mi] * p[mo]); break;
      case Kind::kPassage: v[k] = mix(cap, rule.x * L); break;
      case Kind::kPowerMean: {
        const double share = passage_share(f, mi + mo, 2, L, cap);
        if (!(p[0] > 0 && p[1] > 0)) { v[k] = mix(cap, L); break; }
        v[k] = std::pow(share * std::pow(p[1], rule.x) + (1 - share) * std::pow(p[0], rule.x), 1 / rule.x);
        break;
      }
      case Kind::kShipped:  // chord_among_passages_mm and darker_shares at the renderer's gamma
      case Kind::kDarkerPower: {
        const double share = passage_share(f, mi + mo, 2, L, cap);
        const double shares[2] = {1 - share, share}, refl[2] = {disc_darker ? 1.0 : 0.0, disc_darker ? 0.0 : 1.0};
        double out[2];
        darker_shares(2, shares, refl, rule.kind == Kind::kShipped ? kDarkerShareGamma : rule.x, out);
        v[k] = std::pow(p[1], out[1]) * std::pow(p[0], out[0]);
        break;
      }
      case Kind::kBentChord:
      case Kind::kBentShares: {  // eight equal-weight quantiles of the standard normal
        constexpr double kZ[4] = {0.15731, 0.48878, 0.88715, 1.53412};
        const double refl[2] = {disc_darker ? 1.0 : 0.0, disc_darker ? 0.0 : 1.0};
        auto value = [&](double share) {
          const double shares[2] = {1 - share, share};
          double out[2];
          darker_shares(2, shares, refl, rule.gamma, out);
          return std::pow(p[1], out[1]) * std::pow(p[0], out[0]);
        };
        double sum = 0;
        for (int n = 0; n < 8; ++n) {
          const double z = n < 4 ? kZ[n] : -kZ[n - 4];
          const double share = passage_share(bent_inside_fraction(d, 0, xi, yi, a, z * rule.x * r), mi + mo, 2, L, cap);
          sum += rule.kind == Kind::kBentChord ? value(share) : share;
        }
        v[k] = rule.kind == Kind::kBentChord ? sum / 8 : value(sum / 8);
        break;
      }
      case Kind::kSoftDarker:
      case Kind::kSoftBoth: {
        const double sigma = rule.x > 0 ? rule.x : -rule.x * L;
        const int grow = rule.kind == Kind::kSoftBoth ? 0 : (disc_darker ? 1 : -1);
        const double ends = soft_member(std::hypot(xi, yi), a, sigma, grow) + soft_member(d, a, sigma, grow);
        const double fs = soft_fraction(d, 0, xi, yi, a, sigma, grow);
        const double share = (ends * L + cap * fs) / (2 * L + cap);
        const double shares[2] = {1 - share, share}, refl[2] = {disc_darker ? 1.0 : 0.0, disc_darker ? 0.0 : 1.0};
        double out[2];
        darker_shares(2, shares, refl, rule.gamma, out);
        v[k] = std::pow(p[1], out[1]) * std::pow(p[0], out[0]);
        break;
      }
      case Kind::kEndChordSplit: {
        if (!(p[0] > 0 && p[1] > 0)) { v[k] = mix(cap, L); break; }
        const int other = 1 - mo;  // relative to the exit point's material
        const double share = passage_share(other ? f : 1 - f, mi == other ? 1 : 0, 2, L, cap);
        v[k] = p[mo] * std::exp(crossed_log_term(std::log(p[other] / p[mo]), share, mi == other ? 1 : 0, other ? f : 1 - f,
                                                 sp[mo], cap));
        break;
      }
    }
  }
}

// Each rule's integral over the ring [d0, d1) of exit points (area-weighted) and every entry point,
// over the disc-free tissue's.
void ring_integrals(const Preset& healthy, const Preset& disc, int wl, double a, double d0, double d1, double L,
                    double* out) {
  const SpatialStack* S[2] = {healthy.stack, disc.stack};
  double rd[2];
  size_t at[2];
  for (int m = 0; m < 2; ++m) {
    const auto co = S[m]->cosines(1.0);
    at[m] = S[m]->el_at(co.c[0], wl);
    rd[m] = S[m]->prof->rd[size_t(co.c[0]) * S[m]->n + wl];
  }
  for (int k = 0; k < kNumRules; ++k) out[k] = 0;
  const RadialRings& g = S[0]->el_rings();
  EndChordSplit sp[2] = {split_log_ratio(&S[0]->el_dens[at[0]], &S[1]->el_dens[at[1]], g, L),
                         split_log_ratio(&S[1]->el_dens[at[1]], &S[0]->el_dens[at[0]], g, L)};
  sp[0].e += 0.5 * std::log(rd[1] / rd[0]);
  sp[1].e += 0.5 * std::log(rd[0] / rd[1]);
  double wsum = 0;
  for (int sd = 0; sd < 5; ++sd) {
    const double d = d0 + (d1 - d0) * (sd + 0.5) / 5, wd = d + 1e-9;
    wsum += wd;
    for (int jr = 0; jr < g.rings; ++jr)
      for (int sub = 0; sub < 4; ++sub) {
        const double r0 = g.edge(jr), r1 = g.edge(jr + 1);
        const double ra = r0 + (r1 - r0) * sub / 4, rb = r0 + (r1 - r0) * (sub + 1) / 4, r = 0.5 * (ra + rb);
        const double area = kPi * (rb * rb - ra * ra);
        const double p[2] = {S[0]->el_dens[at[0] + jr] * rd[0], S[1]->el_dens[at[1] + jr] * rd[1]};
        constexpr int kAngles = 128;
        for (int ia = 0; ia < kAngles; ++ia) {
          const double phi = 2 * kPi * (ia + 0.5) / kAngles;
          double v[kNumRules];
          rule_values(d, d + r * std::cos(phi), r * std::sin(phi), r, a, L, p, sp, rd[1] < rd[0], v);
          for (int k = 0; k < kNumRules; ++k) out[k] += wd * v[k] * area / kAngles;
        }
      }
  }
  for (int k = 0; k < kNumRules; ++k) out[k] /= wsum * rd[0];
}

}  // namespace

int run(int argc, char** argv) {
  std::string runs = "benchmarks/lesion_runs", preset = "blood_spot";
  bool rings = false;
  int base = 0;  // the rule the runs were rendered with: each rule's prediction is the run's value plus its change
  for (int i = 1; i < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--rings") { rings = true; --i; continue; }
    if (k == "--unraised-runs") { base = 1; --i; continue; }  // runs rendered before darker_shares (2026-11-28)
    if (i + 1 >= argc) { std::fprintf(stderr, "lesion_rules: %s needs a value\n", k.c_str()); return 2; }
    if (k == "--runs") runs = argv[i + 1];
    else if (k == "--preset") preset = argv[i + 1];
    else { std::fprintf(stderr, "lesion_rules: unknown option %s\n", k.c_str()); return 2; }
  }
  const auto healthy = load_preset("lateral_tongue"), disc = load_preset(preset);
  if (!healthy->stack || !disc->stack) { std::fprintf(stderr, "lesion_rules: no spatial stack\n"); return 2; }
  const double L = differing_depth_mm(healthy->scene.materials[0].stack, disc->scene.materials[0].stack);
  const double band_nm[3] = {450, 560, 630};
  int pass[kNumRules] = {}, total = 0;
  std::printf("lesion_rules: %s in lateral_tongue, passage L = %.2f mm, runs in %s\n", preset.c_str(), L, runs.c_str());
  for (const char* a_text : {"0.25", "0.5", "1", "2", "5"}) {
    const std::string file = runs + "/spatial_lesion_" + preset + "_" + a_text + "mm.json";
    std::ifstream in(file);
    if (!in) { std::printf("  %s mm: no run (%s)\n", a_text, file.c_str()); continue; }
    nlohmann::json x;
    try {
      x = nlohmann::json::parse(in).at("extra");
    } catch (const std::exception& e) {
      throw std::runtime_error(file + ": " + e.what());
    }
    const auto& edges = x["ring_edges_mm"];
    const double a = std::stod(a_text);
    int disc_pass[kNumRules] = {}, disc_total = 0;
    for (int b = 0; b < 3; ++b) {
      const int wl = disc->scene.grid().index_of(band_nm[b]);
      for (size_t k = 0; k + 1 < edges.size(); ++k) {
        double v[kNumRules];
        ring_integrals(*healthy, *disc, wl, a, edges[k], edges[k + 1], L, v);
        const double mc = x["forward_mc"]["contrast"][b][k], se = x["forward_mc"]["se"][b][k];
        const double sp = x["spatial"]["contrast"][b][k], sse = x["spatial"]["se"][b][k];
        const double tol = mc_tolerance(0.02, mc, std::sqrt(se * se + sse * sse));
        for (int r = 0; r < kNumRules; ++r) disc_pass[r] += std::abs(sp + v[r] - v[base] - mc) <= tol;
        if (rings)
          {
          std::printf("    %.0f nm, %.2f-%.2f mm: Monte Carlo %.3f (tolerance %.3f), rendered %.3f; rules:", band_nm[b],
                      double(edges[k]), double(edges[k + 1]), mc, tol, sp);
          for (int r = 0; r < kNumRules; ++r) std::printf(" %.3f", sp + v[r] - v[base]);
          std::printf("\n");
        }
        ++disc_total;
      }
    }
    std::printf("  %s mm:", a_text);
    for (int r = 0; r < kNumRules; ++r) { std::printf(" %d", disc_pass[r]); pass[r] += disc_pass[r]; }
    std::printf(" of %d\n", disc_total);
    total += disc_total;
  }
  for (int r = 0; r < kNumRules; ++r) std::printf("%-28s %d of %d rings\n", kRules[r].name, pass[r], total);
  return 0;
}

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {  // a run's JSON that does not parse or lacks a field
    std::fprintf(stderr, "lesion_rules: %s\n", e.what());
    return 2;
  }
}
