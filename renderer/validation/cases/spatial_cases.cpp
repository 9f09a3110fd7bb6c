// Validation of the spatial transport of layered tissue (docs/layered-tissue.md, "Lateral
// transport") against the independent forward photon Monte Carlo of renderer/validation/references/forward_mc.h:
//   spatial_fluorescence_pencil  a scattering, fluorescent two-layer slab under a normal pencil beam
//     at 405 nm: the fluorescence exitance per ring around the beam (its share of all of it) as the
//     spatial transport's tables give it (excitation leg convolved with emission leg, summed over
//     depth slices with the table's direct fluorescence as weights), filled with four seeds, against
//     the forward Monte Carlo in eight batches; every ring within 3 combined standard errors (the
//     total, which is the position-free table's, is reported beside).
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "renderer/validation/harness/bench_check.h"
#include "renderer/validation/harness/bench_support.h"
#include "renderer/validation/cases/closed_form_cases.h"
#include "renderer/validation/references/forward_mc.h"
#include "renderer/validation/cases/spatial_cases.h"
#include "renderer/core/files/json_node.h"
#include "renderer/image/image_file.h"
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/spatial/spatial_tables.h"
#include "renderer/render/stack/stack_response.h"
#include "renderer/render/stack/stack_response_cache.h"
#include "renderer/render/trace/rng.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

namespace {

using nlohmann::json;

// The forward Monte Carlo's batches: their spread is its standard error (32 give it within about
// 13 %); the profiles' fills: their spread is the tables' noise.
constexpr int kMcBatches = 32, kFillSeeds = 4;

// Ring edges (mm) of the pencil-beam comparison.
std::vector<double> pencil_rings() {
  return {0, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 7.0, 10.0};
}

// The slab: a fluorescent epithelium over a fluorescent stroma, quantum yields 1 so that the forward
// photons give fluorescence often enough to resolve rings; smooth top.
json pencil_slab(long long profile_photons) {
  return {{"type", "layered_tissue"},
          {"transport", "spatial"},
          {"profile_photons", profile_photons},
          {"layers",
           {{{"name", "epithelium"}, {"thickness_mm", 0.3}, {"ior", 1.37},
             {"scattering", {{"g", 0.8}, {"mus_per_mm", 10.0}}},
             {"absorption", {{"baseline_per_mm", 0.02}}},
             {"fluorophores", {{{"name", "NADH"}, {"mua_per_mm", 0.3}, {"quantum_yield", 1.0}}}}},
            {{"name", "stroma"}, {"thickness_mm", "infinite"}, {"ior", 1.37},
             {"scattering", {{"g", 0.9}, {"mus_per_mm", 20.0}}},
             {"absorption", {{"baseline_per_mm", 0.05}}},
             {"fluorophores", {{{"name", "collagen"}, {"mua_per_mm", 0.2}, {"quantum_yield", 1.0}}}}}}}};
}


struct RingStats {
  std::vector<double> mean, se;
  double total = 0, total_se = 0;
};

RingStats stats_of(const std::vector<std::vector<double>>& rings, const std::vector<double>& totals) {
  RingStats s;
  const size_t R = rings.front().size(), K = rings.size();
  s.mean.assign(R, 0.0);
  s.se.assign(R, 0.0);
  for (size_t i = 0; i < R; ++i) {
    double a = 0, b = 0;
    for (const auto& r : rings) {
      a += r[i];
      b += r[i] * r[i];
    }
    s.mean[i] = a / K;
    s.se[i] = std::sqrt(std::max(0.0, (b / K - s.mean[i] * s.mean[i]) / (K - 1)));
  }
  double a = 0, b = 0;
  for (double t : totals) {
    a += t;
    b += t * t;
  }
  s.total = a / K;
  s.total_se = std::sqrt(std::max(0.0, (b / K - s.total * s.total) / (K - 1)));
  return s;
}

// Shares of each ring in a tally summed over bins; the total in photons per incident photon times
// the source's shape sum (the unit the table's exitance is in).
std::vector<double> ring_shares(const std::vector<double>& tally, int n, size_t rings, double* total) {
  std::vector<double> r(rings, 0.0);
  double t = 0;
  for (size_t i = 0; i < rings; ++i)
    for (int w = 0; w < n; ++w) r[i] += tally[i * n + w];
  for (double v : r) t += v;
  for (double& v : r) v = t > 0 ? v / t : 0.0;
  *total = t;
  return r;
}

// What the spatial transport's tables give for the pencil beam: the fluorescence exitance per ring
// (shares) and its total, by sampling depth slice, emission bin and viewing cosine in proportion to
// the table's direct fluorescence times the slice's weight, and the two legs' radii.
std::vector<double> predicted_pencil(const SpatialStack& S, const StackResponse& R, const std::vector<double>& edges, uint64_t seed,
                                     double* total) {
  const int n = S.n, Z = S.Z, Q = 64;
  std::vector<double> w;  // [(q * n + em) * Z + z]
  w.assign(size_t(Q) * n * Z, 0.0);
  const auto b = R.weights(1.0);
  double T = 0;
  for (int q = 0; q < Q; ++q) {
    const double mu = (q + 0.5) / Q;
    const auto a = R.weights(mu);
    for (int em = 0; em < n; ++em) {
      const double d = R.direct_at(0, a, b, em) * 2.0 * kPi * mu / Q;
      const double sum = S.slice_sum(0, S.cosines(mu), S.cosines(1.0), em);
      if (!(d > 0 && sum > 0)) continue;
      for (int z = 0; z < Z; ++z) {
        const double v = d * S.slice_weight(0, S.cosines(mu), S.cosines(1.0), em, z) / sum;
        w[(size_t(q) * n + em) * Z + z] = v;
        T += v;
      }
    }
  }
  *total = T;
  DiscreteDistribution pick(w);
  std::vector<double> rings(edges.size() - 1, 0.0);
  const long long M = 2000000;
  Rng rng(seed, 0x50454E43ULL);
  for (long long i = 0; i < M; ++i) {
    const int cell = pick.sample(rng.next_double());
    const int z = cell % Z, em = (cell / Z) % n, q = cell / (Z * n);
    const double mu = (q + 0.5) / Q;
    const auto co = S.prof->weights(mu);
    const int c = rng.next_double() < co.w[0] ? co.c[0] : co.c[1];
    const double r2 = radial::sample(S.leg_rings(), &S.leg_cdf[S.leg_at(c, em, z)], rng.next_double(), rng.next_double());
    const double r1 = radial::sample(S.leg_rings(), &S.ex_cdf[S.ex_at(0, 0, z)], rng.next_double(), rng.next_double());
    const double r = std::sqrt(std::max(0.0, r1 * r1 + r2 * r2 + 2.0 * r1 * r2 * std::cos(2.0 * kPi * rng.next_double())));
    if (r >= edges.back()) continue;
    const size_t k = size_t(std::upper_bound(edges.begin(), edges.end(), r) - edges.begin()) - 1;
    rings[k] += 1.0 / M;
  }
  return rings;
}

}  // namespace

CheckCaseResult spatial_fluorescence_pencil(long long samples, uint64_t seed) {
  CheckCaseResult r;
  r.name = "spatial_fluorescence_pencil";
  r.samples = samples;
  const std::vector<double> edges = pencil_rings();
  const size_t R = edges.size() - 1;
  const json spd = {{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 10}};
  // The tables, filled with four seeds (the spread of their predictions is their noise).
  std::vector<std::vector<double>> pred;
  std::vector<double> pred_total;
  int n = 0;
  std::vector<double> source;
  for (int f = 0; f < kFillSeeds; ++f) {
    Scene sc = bench::stack_bench_scene(pencil_slab(std::max<long long>(100, samples / 40)), spd, 380, 700);
    RenderTables t(sc);
    // Another seed than the renderer's: refill the profiles from this scene's tables.
    StackProfileOptions o;
    o.photons = int(std::max<long long>(100, samples / 40));
    o.seed += uint64_t(f) * 7919;
    auto prof = build_stack_profiles(t.materials[0].stack, t.materials[0], t.n, o);
    auto S = build_spatial_stack(t.materials[0].stack, prof, t.light_shape);
    double total = 0;
    pred.push_back(predicted_pencil(*S, *t.materials[0].stack.response, edges, seed + f, &total));
    pred_total.push_back(total);
    if (f == 0) {
      n = t.n;
      for (float v : t.light_shape[0]) source.push_back(v);
      // The forward photons.
      ForwardSetup s;
      s.outside.st = &t.materials[0].stack;
      s.n = n;
      s.source = source;
      s.ring_edges = edges;
      std::vector<std::vector<double>> mc;
      std::vector<double> mc_total;
      double shape_sum = 0;
      for (double v : source) shape_sum += v;
      // Batches of at least 50 000 photons: the outer rings hold about 1 % of the fluorescence, and
      // with fewer photons per batch their tallies are too sparse for a batch spread to be a
      // standard error.
      const int batches = int(std::clamp<long long>(samples / 50000, 8, kMcBatches));
      for (int b = 0; b < batches; ++b) {
        ForwardTally ft = run_forward_mc(s, std::max<long long>(1000, samples / batches), seed * 1000 + b);
        double tot = 0;
        mc.push_back(ring_shares(ft.fluor, n, R, &tot));
        mc_total.push_back(tot * shape_sum / double(ft.photons));
      }
      RingStats m = stats_of(mc, mc_total);
      r.extra["forward_mc"] = {{"shares", m.mean}, {"se", m.se}, {"total", m.total}, {"total_se", m.total_se}};
    }
  }
  RingStats p = stats_of(pred, pred_total);
  const auto& m = r.extra["forward_mc"];
  for (size_t i = 0; i < R; ++i) {
    const double ref = m["shares"][i], se = std::hypot(double(m["se"][i]), p.se[i]);
    char q[120];
    std::snprintf(q, sizeof q, "share of fluorescence exitance, ring %.2f-%.2f mm", edges[i], edges[i + 1]);
    r.checks.push_back({q, p.mean[i], ref, 3.0 * se});
  }
  // The total is the position-free table's (renderer/render/stack/stack_response.h), reported beside.
  r.extra["spatial"] = {{"shares", p.mean}, {"se", p.se}, {"total", p.total}, {"total_se", p.total_se}};
  r.extra["ring_edges_mm"] = edges;
  r.extra["position_free"] = "all of it in the first ring";
  return r;
}

// ---------------------------------------------------------------------------------------------
// A lesion of finite size: a disc of one layered preset inside another, lit uniformly.
namespace {

// One batch's tallies per ring, of the lesion scene and of the healthy reference run with the same photons.
struct RingPair {
  std::vector<double> lesion, healthy;
};

// Per ring, the ratio of the summed tallies over the batches (lesion over healthy) and its standard
// error by the delta method: se^2 = K / (K - 1) sum_b (l_b - R h_b)^2 / H^2, H the summed healthy tally.
RingStats ratio_stats(const std::vector<RingPair>& b) {
  RingStats s;
  const size_t R = b.front().lesion.size(), K = b.size();
  s.mean.assign(R, 0.0);
  s.se.assign(R, 0.0);
  for (size_t i = 0; i < R; ++i) {
    double L = 0, H = 0;
    for (const auto& p : b) {
      L += p.lesion[i];
      H += p.healthy[i];
    }
    if (!(H > 0)) continue;
    const double ratio = L / H;
    double v = 0;
    for (const auto& p : b) v += (p.lesion[i] - ratio * p.healthy[i]) * (p.lesion[i] - ratio * p.healthy[i]);
    s.mean[i] = ratio;
    s.se[i] = std::sqrt(v * double(K) / double(K - 1)) / H;
  }
  return s;
}

struct LesionCase {
  std::string inside = "dysplasia", outside = "lateral_tongue";
  double a_mm = 1;
  bool fluorescence = false;  // false: broadband light, elastic profile; true: 405 nm LED, fluorescence
  double theta_deg = 10;      // the light's polar angle
  // Walks per node of the rendered materials' tables. The table's node nearest the normal, where
  // the camera looks, is its noisiest (docs/layered-tissue.md, Limitations): at 40 000 its noise is
  // a few per cent, as large as the Monte Carlo's error bars at full counts, so full runs use more.
  long long table_photons = 40000;
};

// The bands each profile is reported in: (lo, hi) nm.
std::vector<std::pair<double, double>> lesion_bands(const LesionCase& c) {
  if (c.fluorescence) return {{480, 700}, {500, 550}, {600, 660}};
  return {{440, 460}, {540, 580}, {620, 640}};
}

// Ring edges around the disc's centre: across the centre and the edge, out to a + 3 mm.
std::vector<double> lesion_rings(double a) {
  std::vector<double> e = {0.0, 0.5 * a};
  for (double d : {-0.75, -0.5, -0.3, -0.15, 0.0, 0.15, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0}) {
    const double r = a + d;
    if (r > e.back() + 1e-9) e.push_back(r);
  }
  return e;
}

// The preset with a smooth wet film (the forward Monte Carlo's interfaces are smooth). Its table is
// filled with 40000 walks per node: at the default 2000 the table's elastic values near normal viewing
// carry about 10 % of fill noise (few walks leave within 17 degrees of the normal), which is the
// position-free table's, not the lateral transport's, and would hide what is checked here.
json smooth_preset(const std::string& preset, const std::string& transport, long long profile_photons,
                   long long table_photons = 40000) {
  json m = {{"type", "layered_tissue"}, {"preset", preset}, {"transport", transport}, {"table_photons", table_photons},
            {"coating", {{"ior", 1.33}, {"roughness", 0.0}, {"thickness_mm", 0.01}}}};
  if (transport == "spatial" && profile_photons > 0) m["profile_photons"] = profile_photons;
  return m;
}

json lesion_light(const LesionCase& c) {
  const double th = c.theta_deg * kPi / 180.0, d = 10.0;
  json spd = c.fluorescence ? json{{"type", "gaussian"}, {"peak_nm", 405}, {"fwhm_nm", 15}} : json{{"type", "constant"}, {"value", 1.0}};
  return {{"spd", spd}, {"radiant_intensity_W_sr", 100.0}, {"profile", {{"half_angle_deg", 60}}},
          {"position", {0.0, -d * std::sin(th), d * std::cos(th)}}, {"target", {0, 0, 0}}};
}

// A disc mask of radius a on a square of half-width h (mm), 2048 texels, anti-aliased so that the
// renderer's bilinear lookup and 0.5 threshold give the circle.
std::filesystem::path write_disc_mask(double a, double h) {
  const int N = 2048;
  std::vector<unsigned char> px(size_t(N) * N);
  const double texel = 2.0 * h / N;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const double X = -h + (x + 0.5) * texel, Y = -h + (y + 0.5) * texel;
      const double cover = std::clamp(0.5 - (std::hypot(X, Y) - a) / texel, 0.0, 1.0);
      px[size_t(y) * N + x] = (unsigned char)std::lround(255.0 * cover);
    }
  char name[96];
  std::snprintf(name, sizeof name, "ofl_disc_%.4f_%.3f.png", a, h);
  const auto file = std::filesystem::temp_directory_path() / name;
  OIIO::ImageSpec spec(N, N, 1, OIIO::TypeDesc::UINT8);
  write_image_file(file, spec, px.data());
  return file;
}

// Per band and ring: the mean signal of the lesion scene over that of healthy tissue, with its
// standard error.
struct Contrast {
  std::vector<std::vector<double>> c, se;  // [band][ring]
};

// The rendered profile: a pinhole straight above the disc's centre, pixels binned by their distance
// from it; each pixel divided by the healthy tissue's image in the same light.
Contrast rendered_contrast(const LesionCase& c, const std::string& transport, int spp, uint64_t seed, long long profile_photons) {
  const auto edges = lesion_rings(c.a_mm);
  const double R = edges.back(), half = R + 15.0;  // the patch reaches beyond where red light travels
  const int W = 160;
  const double H = 0.5;  // camera height, m
  // The volume walk's reflectance is rendered band by band, each with film bands covering that band
  // alone (the lanes are drawn where the film records, so all eight of every sample fall in the band:
  // a fourth to a sixteenth of the cost at equal noise).
  const bool per_band = transport == "volume" && !c.fluorescence;
  auto scene_json = [&](bool lesion, double out_lo, double out_hi) {
    json mats = {{"healthy", smooth_preset(c.outside, transport, profile_photons, c.table_photons)},
                 {"lesion", smooth_preset(c.inside, transport, profile_photons, c.table_photons)}};
    mats["tissue"] = lesion ? json{{"type", "regions"}, {"base", "healthy"},
                                   {"regions", {{{"mask", write_disc_mask(c.a_mm, half).string()}, {"material", "lesion"}}}}}
                            : json{{"type", "regions"}, {"base", "healthy"}, {"regions", {{{"mask", write_disc_mask(0.0, half).string()}, {"material", "lesion"}}}}};
    // The volume walk's reflectance without re-emission (the fluorophores still absorb): its
    // fluorescence sub-walks would cost 30 times the reflectance itself and are not looked at.
    const bool fluorescence = c.fluorescence || transport != "volume";
    return json{{"format", "oralfluor-scene"}, {"version", 1},
                {"integrator", {{"spp", spp}, {"seed", seed}, {"max_depth", 1}, {"fluorescence", fluorescence},
                                {"wavelengths", {{"min_nm", 380}, {"max_nm", 700}, {"step_nm", 5}}},
                                {"output_bands", {{"min_nm", out_lo}, {"max_nm", out_hi}, {"step_nm", 5}}}}},
                {"camera", {{"position", {0, 0, H}}, {"look_at", {0, 0, 0}}, {"up", {0, 1, 0}},
                            {"fov_deg", 2.0 * std::atan(R / 1000.0 / H) * 180.0 / kPi}, {"resolution", {W, W}}}},
                {"materials", mats},
                {"geometry", {{{"type", "quad"}, {"center", {0, 0, 0}}, {"u", {2.0 * half / 1000.0, 0, 0}}, {"v", {0, 2.0 * half / 1000.0, 0}},
                               {"material", "tissue"}}}},
                {"lights", {lesion_light(c)}}};
  };
  const auto bands = lesion_bands(c);
  std::vector<bench::Rendered> lesion, healthy;  // one pair, or one per band
  for (size_t i = 0; i < (per_band ? bands.size() : 1); ++i) {
    const double lo = per_band ? bands[i].first : 380, hi = per_band ? bands[i].second : 700;
    lesion.push_back(bench::render_json(scene_json(true, lo + 2.5, hi - 2.5), "lesion"));
    healthy.push_back(bench::render_json(scene_json(false, lo + 2.5, hi - 2.5), "healthy"));
  }
  const size_t rings = edges.size() - 1;
  Contrast out;
  for (size_t bi = 0; bi < bands.size(); ++bi) {
    const SpectralImage& L = lesion[per_band ? bi : 0].result.image;
    const SpectralImage& Hh = healthy[per_band ? bi : 0].result.image;
    const double lo = bands[bi].first, hi = bands[bi].second;  // (named, not bound: the lambda below reads them)
    // Per ring: the lesion image's mean over the healthy image's mean in the same ring (the patch is
    // finite, so the healthy image is not quite uniform either), with the ratio's standard error.
    std::vector<double> s(rings, 0.0), s2(rings, 0.0), h(rings, 0.0), h2(rings, 0.0), cnt(rings, 0.0);
    auto band_value = [&](const SpectralImage& im, size_t at) {
      double v = 0;
      for (int i = 0; i < im.bands(); ++i) {
        if (im.band_nm[i] < lo || im.band_nm[i] > hi) continue;
        v += c.fluorescence ? im.fluorescence[at + i] : im.data[at + i] - im.fluorescence[at + i];
      }
      return v;
    };
    for (int y = 0; y < W; ++y)
      for (int x = 0; x < W; ++x) {
        const double X = (2.0 * (x + 0.5) / W - 1.0) * R, Y = (1.0 - 2.0 * (y + 0.5) / W) * R, r = std::hypot(X, Y);
        if (r >= R) continue;
        const size_t k = size_t(std::upper_bound(edges.begin(), edges.end(), r) - edges.begin()) - 1;
        const size_t at = (size_t(y) * W + x) * L.bands();
        const double a = band_value(L, at), b = band_value(Hh, at);
        s[k] += a;
        s2[k] += a * a;
        h[k] += b;
        h2[k] += b * b;
        cnt[k] += 1;
      }
    std::vector<double> cc(rings), ee(rings);
    for (size_t k = 0; k < rings; ++k) {
      const double n = cnt[k], ma = s[k] / n, mh = h[k] / n;
      const double va = std::max(0.0, s2[k] / n - ma * ma) / (n - 1), vh = std::max(0.0, h2[k] / n - mh * mh) / (n - 1);
      cc[k] = ma / mh;
      ee[k] = cc[k] * std::sqrt(va / (ma * ma) + vh / (mh * mh));
    }
    out.c.push_back(cc);
    out.se.push_back(ee);
  }
  return out;
}

// The forward Monte Carlo's profile, in the same bands and rings: the radiance leaving along the
// normal (the camera of these cases looks straight down, within half a degree), from the Monte
// Carlo's local estimate (forward_mc.h), per unit area of ring, over the healthy tissue's (a run
// without the disc). Lesion and healthy tissue send their light into different angles, so exitance
// would not do, and neither quite does a cone: just inside the 1 mm blood spot's edge the light
// within 37 degrees of the normal read 0.48, within 14 degrees 0.42 (docs/layered-tissue.md, "How it
// was checked"). For reflectance each band is run on its own, the source
// restricted to the band's bins (the light is flat); fluorescence bands share one run of the 405 nm
// LED. The profiles of the light leaving in all directions, within 37 and within 14 degrees of the
// normal (photon counts) are kept beside.
Contrast forward_contrast(const LesionCase& c, long long photons, uint64_t seed, nlohmann::json* beside) {
  const auto edges = lesion_rings(c.a_mm);
  const json spd = lesion_light(c)["spd"];
  Scene sc = bench::stack_bench_scene(smooth_preset(c.outside, "table", 0), spd, 380, 700);
  Scene sl = bench::stack_bench_scene(smooth_preset(c.inside, "table", 0), spd, 380, 700);
  RenderTables th(sc), tl(sl);
  ForwardSetup s;
  s.outside.st = &th.materials[0].stack;
  s.inside.st = &tl.materials[0].stack;
  s.radius_mm = c.a_mm;
  s.n = th.n;
  s.theta_deg = c.theta_deg;
  s.half_mm = edges.back() + (c.fluorescence ? 8.0 : 12.0);
  s.focus_mm = edges.back();
  s.fluorescence = c.fluorescence;
  s.ring_edges = edges;
  s.cone_cos = 0.8;
  const size_t rings = edges.size() - 1;
  const auto bands = lesion_bands(c);
  const WavelengthGrid& g = sc.grid();
  auto in_band = [&](int w, size_t i) { return g.wavelength(w) >= bands[i].first && g.wavelength(w) <= bands[i].second; };
  auto band_sum = [&](const std::vector<double>& t, size_t k, size_t i) {
    double v = 0;
    for (int w = 0; w < s.n; ++w)
      if (in_band(w, i)) v += t[k * s.n + w];
    return v;
  };
  // The healthy reference: the same photons (the same seeds) in the tissue without the disc, tallied on
  // the same rings. Photons that never reach the disc's layers take the same paths in both, so the
  // ratio's noise is only that of the light the disc changes (common random numbers). With an
  // independent healthy run, its noise was shared by every ring of a batch and moved whole profiles
  // together (docs/layered-tissue.md, "How it was checked").
  ForwardSetup hs = s;
  hs.radius_mm = 0;
  // Per band and tally (along the normal, all directions, within 37 degrees, within 14 degrees), the
  // batches' ring sums.
  constexpr int kTallies = 4;
  std::vector<std::array<std::vector<RingPair>, kTallies>> batches(bands.size());
  const size_t runs = c.fluorescence ? 1 : bands.size();
  for (size_t run = 0; run < runs; ++run) {
    std::vector<double> source;
    for (int w = 0; w < s.n; ++w) source.push_back(c.fluorescence || in_band(w, run) ? double(th.light_shape[0][w]) : 0.0);
    s.source = hs.source = source;
    for (int b = 0; b < kMcBatches; ++b) {
      const long long np = std::max<long long>(1000, photons / (kMcBatches * long(runs)));
      const uint64_t batch_seed = seed * 1000 + 37 * run + b;
      const ForwardTally t = run_forward_mc(s, np, batch_seed);
      const ForwardTally h = run_forward_mc(hs, np, batch_seed);
      for (size_t i = 0; i < bands.size(); ++i) {
        if (!c.fluorescence && i != run) continue;
        for (int tally = 0; tally < kTallies; ++tally) {
          auto pick = [&](const ForwardTally& x) -> const std::vector<double>& {
            const std::vector<double>* elastic[] = {&x.elastic_normal, &x.elastic, &x.elastic_cone, &x.elastic_narrow};
            const std::vector<double>* fluor[] = {&x.fluor_normal, &x.fluor, &x.fluor_cone, &x.fluor_narrow};
            return *(c.fluorescence ? fluor : elastic)[tally];
          };
          RingPair v;
          for (size_t k = 0; k < rings; ++k) {
            v.lesion.push_back(band_sum(pick(t), k, i));
            v.healthy.push_back(band_sum(pick(h), k, i));
          }
          batches[i][tally].push_back(v);
        }
      }
    }
  }
  Contrast out;
  const char* names[] = {"", "all_directions", "within_37_degrees", "within_14_degrees"};
  for (size_t i = 0; i < bands.size(); ++i) {
    const RingStats st = ratio_stats(batches[i][0]);
    out.c.push_back(st.mean);
    out.se.push_back(st.se);
    for (int tally = 1; tally < kTallies; ++tally) {
      const RingStats o = ratio_stats(batches[i][tally]);
      (*beside)[names[tally]]["contrast"].push_back(o.mean);
      (*beside)[names[tally]]["se"].push_back(o.se);
    }
  }
  return out;
}

}  // namespace

CheckCaseResult spatial_lesion_disc(const std::string& inside, double a_mm, bool fluorescence, long long samples, uint64_t seed,
                                    const std::string& transport) {
  LesionCase c;
  c.inside = inside;
  c.a_mm = a_mm;
  c.fluorescence = fluorescence;
  c.table_photons = std::clamp<long long>(samples / 80, 40000, 400000);
  CheckCaseResult r;
  char nm[96];
  std::snprintf(nm, sizeof nm, "%s_lesion_%s_%gmm%s", transport.c_str(), inside.c_str(), a_mm, fluorescence ? "_fluorescence" : "");
  r.name = nm;
  r.samples = samples;
  // The volume walk costs far more per sample than the profiles: it renders a tenth of the samples
  // (at full counts its noise is still below the Monte Carlo's).
  const int spp = int(std::clamp<long long>(samples / (transport == "volume" ? 400000 : 20000), 4, 4096));
  const long long profile_photons = std::max<long long>(2000, samples / 200);
  nlohmann::json beside = json::object();
  const Contrast mc = forward_contrast(c, samples, seed, &beside);
  const Contrast sp = rendered_contrast(c, transport, spp, seed, profile_photons);
  const Contrast pf = rendered_contrast(c, "table", std::max(4, spp / 8), seed, 0);
  const auto edges = lesion_rings(a_mm);
  const auto bands = lesion_bands(c);
  for (size_t i = 0; i < bands.size(); ++i)
    for (size_t k = 0; k + 1 < edges.size(); ++k) {
      char q[160];
      std::snprintf(q, sizeof q, "%s %g-%g nm, ring %.3f-%.3f mm (position-free %.3f)", fluorescence ? "fluorescence" : "reflectance",
                    bands[i].first, bands[i].second, edges[k], edges[k + 1], pf.c[i][k]);
      const double ref = mc.c[i][k], se = std::hypot(mc.se[i][k], sp.se[i][k]);
      r.checks.push_back({q, sp.c[i][k], ref, mc_tolerance(0.02, ref, se)});
    }
  r.extra["ring_edges_mm"] = edges;
  r.extra["forward_mc"] = {{"contrast", mc.c}, {"se", mc.se}, {"along", "the normal (local estimate)"}};
  r.extra["forward_mc"].update(beside);
  r.extra[transport] = {{"contrast", sp.c}, {"se", sp.se}};
  r.extra["position_free"] = {{"contrast", pf.c}, {"se", pf.se}};
  return r;
}

}  // namespace ofl
