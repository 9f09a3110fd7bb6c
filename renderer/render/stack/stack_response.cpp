// The tabulated stack response (see stack_response.h).
#include "renderer/render/stack/stack_response.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>

#include "renderer/core/process/progress.h"
#include "renderer/render/stack/stack_fill.h"
#include "renderer/render/stack/stack_response_cache.h"

namespace ofl {

namespace {

// Collision tallies of one walk batch: lane x depth bin.
struct FluenceTally {
  const DepthBins& bins;
  double* t;  // [lane * bins + b]
  void moved(const glm::dvec3&, double) {}
  void collision(const WalkState& s, const LaneCoefficients&, const WalkLanes& lanes) {
    int b = bins.find(s.layer, s.depth);
    if (b < 0) return;
    for (int k = 0; k < lanes.count; ++k) t[size_t(k) * bins.size() + b] += lanes.w[k];
  }
  void base_vertex(const WalkState&, const WalkLanes&) {}
};

double node_mu(int k, int nodes) { return (k + 0.5) / nodes; }

// 2 pi integral over the hemisphere of the tent weight of node k times mu.
double tent_norm(const StackResponse& r, int k) {
  const int steps = 20000;
  double s = 0;
  for (int j = 0; j < steps; ++j) {
    double mu = (j + 0.5) / steps;
    StackResponse::Weights w = r.weights(mu);
    for (int c = 0; c < 2; ++c)
      if (w.k[c] == k) s += w.w[c] * mu;
  }
  return 2.0 * kPi * s / steps;
}

// A launch cosine for node k with density proportional to its tent weight times mu (the weight the
// exits are deposited with): both directions of the table are then the same projection, so the
// table of a reciprocal stack is symmetric, near grazing too. Rejection from the tent's support.
double launch_cosine(const StackResponse& r, int k, Rng& rng) {
  const int N = r.nodes;
  const double lo = k == 0 ? 0.0 : node_mu(k - 1, N), hi = k == N - 1 ? 1.0 : node_mu(k + 1, N);
  for (;;) {
    double mu = lo + (hi - lo) * rng.next_double();
    StackResponse::Weights w = r.weights(mu);
    double phi = (w.k[0] == k ? w.w[0] : 0.0) + (w.k[1] == k && w.k[1] != w.k[0] ? w.w[1] : 0.0);
    if (rng.next_double() * hi < phi * mu) return mu;
  }
}

// Raw Monte Carlo sums, per node: fluence tallies [node][wl][bin] and exit deposits [node][exit node][wl].
struct WalkSums {
  std::vector<double> fluence, exits;
};

// The walks of one (node, wavelength group) job.
void run_job(const StackTables& st, const MaterialTables& mt, int n, const DepthBins& bins, const StackResponseOptions& opt,
             const StackResponse& r, int node, int group, WalkSums& sums) {
  const int first_wl = group * kWalkLanes, count = std::min(kWalkLanes, n - first_wl);
  const int B = bins.size(), N = opt.nodes;
  std::vector<double> tally(size_t(count) * B, 0.0), exits(size_t(count) * N, 0.0);
  FluenceTally visitor{bins, tally.data()};
  const StackWalker walker = StackWalker(st, mt, n, WalkMode::kImportance).with_similarity_after(opt.similarity_after);
  const uint64_t job = uint64_t(node) * 4096 + uint64_t(group);
  for (int p = 0; p < opt.photons; ++p) {
    if ((p & 1023) == 0 && interrupt_requested()) return;  // the table is dropped (fill_stack_response)
    Rng rng(opt.seed, Rng::stream_for(job, uint64_t(p)));
    const double mu = launch_cosine(r, node, rng);
    launch_group(st, walker, first_wl, count, rng, downward(mu), visitor, [&](const WalkResult& res, const WalkLanes& lanes) {
      StackResponse::Weights w = r.weights(res.dir.z);
      for (int k = 0; k < count; ++k)
        for (int c = 0; c < 2; ++c) exits[size_t(k) * N + w.k[c]] += double(lanes.w[k]) * w.w[c];
    });
  }
  for (int k = 0; k < count; ++k) {
    const int wl = first_wl + k;
    for (int b = 0; b < B; ++b) sums.fluence[(size_t(node) * n + wl) * B + b] = tally[size_t(k) * B + b] / opt.photons;
    for (int o = 0; o < N; ++o) sums.exits[(size_t(node) * N + o) * n + wl] = exits[size_t(k) * N + o] / opt.photons;
  }
}

void fill_elastic(const WalkSums& sums, const StackResponseOptions& opt, StackResponse& r) {
  const int N = r.nodes, n = r.n;
  std::vector<double> norm(N);
  for (int k = 0; k < N; ++k) norm[k] = tent_norm(r, k);
  r.elastic.assign(size_t(N) * N * n, 0.0f);
  for (int o = 0; o < N; ++o)
    for (int i = 0; i < N; ++i)
      for (int wl = 0; wl < n; ++wl) {
        double f = sums.exits[(size_t(o) * N + i) * n + wl] / norm[i];
        if (opt.symmetrize) f = 0.5 * (f + sums.exits[(size_t(i) * N + o) * n + wl] / norm[o]);
        r.elastic[r.cell(o, i) * n + wl] = float(f);
      }
}

void fill_fluorescence(const StackTables& st, const DepthBins& bins, const WalkSums& sums, StackResponse& r) {
  const int N = r.nodes, n = r.n, B = bins.size();
  r.fluor.assign(size_t(N) * N * n * n, 0.0f);
  const auto sigma = layer_emission(st, n);
  // Camera-side importance per bin: (n_ambient / n_layer)^2 / dz.
  std::vector<double> cam(B);
  for (int b = 0; b < B; ++b) {
    double ratio = st.ambient_ior / st.layers[bins.layer[b]].ior;
    cam[b] = ratio * ratio / (bins.hi[b] - bins.lo[b]);
  }
  tbb::parallel_for(0, N * N, [&](int oi) {
    const int o = oi / N, i = oi % N;
    const double scale = 1.0 / (4.0 * kPi);
    std::vector<double> a(B);
    for (int l = 0; l < int(st.layers.size()); ++l) {
      if (sigma[l].empty()) continue;
      const int b0 = bins.first[l], b1 = bins.end[l];
      for (int em = 1; em < n; ++em) {
        const double* to = &sums.fluence[(size_t(o) * n + em) * B];
        for (int b = b0; b < b1; ++b) a[b] = to[b] * cam[b];
        float* row = &r.fluor[(r.cell(o, i) * n + em) * n];
        for (int ex = 0; ex < em; ++ex) {
          const float s = sigma[l][size_t(em) * n + ex];
          if (s == 0) continue;
          const double* ti = &sums.fluence[(size_t(i) * n + ex) * B];
          double dot = 0;
          for (int b = b0; b < b1; ++b) dot += a[b] * ti[b];
          row[ex] += float(scale * s * dot);
        }
      }
    }
  });
}

void fill_sums_and_direct(const std::vector<std::vector<float>>& light_shapes, StackResponse& r) {
  const int N = r.nodes, n = r.n;
  const size_t cells = size_t(N) * N;
  r.fluor_sum.assign(cells * n, 0.0f);
  r.fluor_cdf.assign(cells * n * n, 1.0f);
  r.direct.assign(light_shapes.size(), std::vector<float>(cells * n, 0.0f));
  for (size_t c = 0; c < cells; ++c)
    for (int em = 0; em < n; ++em) {
      const float* row = &r.fluor[(c * n + em) * n];
      float* cdf = &r.fluor_cdf[(c * n + em) * n];
      double acc = 0;
      for (int ex = 0; ex < em; ++ex) {
        acc += row[ex];
        cdf[ex] = float(acc);
      }
      r.fluor_sum[c * n + em] = float(acc);
      for (int ex = 0; ex < em; ++ex) cdf[ex] = acc > 0 ? float(cdf[ex] / acc) : 1.0f;
      for (size_t g = 0; g < light_shapes.size(); ++g) {
        double d = 0;
        for (int ex = 0; ex < em; ++ex) d += double(row[ex]) * light_shapes[g][ex];
        r.direct[g][c * n + em] = float(d);
      }
    }
}

}  // namespace

StackResponse::Weights StackResponse::weights(double mu) const {
  Weights w;
  double x = std::clamp(mu, 0.0, 1.0) * nodes - 0.5;
  if (x <= 0) {
    w.k[0] = w.k[1] = 0;
    return w;
  }
  if (x >= nodes - 1) {
    w.k[0] = w.k[1] = nodes - 1;
    return w;
  }
  int k = int(x);
  float t = float(x - k);
  w.k[0] = k;
  w.k[1] = k + 1;
  w.w[0] = 1.0f - t;
  w.w[1] = t;
  return w;
}

float StackResponse::elastic_at(const Weights& a, const Weights& b, int wl) const {
  float s = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) s += a.w[i] * b.w[j] * elastic[cell(a.k[i], b.k[j]) * n + wl];
  return s;
}

float StackResponse::fluor_sum_at(const Weights& a, const Weights& b, int em) const {
  float s = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) s += a.w[i] * b.w[j] * fluor_sum[cell(a.k[i], b.k[j]) * n + em];
  return s;
}

float StackResponse::direct_at(int group, const Weights& a, const Weights& b, int em) const {
  const std::vector<float>& d = direct[group];
  float s = 0;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) s += a.w[i] * b.w[j] * d[cell(a.k[i], b.k[j]) * n + em];
  return s;
}

int StackResponse::sample_excitation(const Weights& a, const Weights& b, int em, double u1, float u2) const {
  // The interpolated row is a mixture of the four corner rows: pick one by its share, then its CDF.
  float share[4], total = 0;
  size_t cells[4];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      cells[2 * i + j] = cell(a.k[i], b.k[j]);
      share[2 * i + j] = a.w[i] * b.w[j] * fluor_sum[cells[2 * i + j] * n + em];
      total += share[2 * i + j];
    }
  double target = u1 * total;
  int c = 0;
  for (; c < 3; ++c) {
    if (target < share[c]) break;
    target -= share[c];
  }
  while (c > 0 && share[c] == 0) --c;
  const float* cdf = &fluor_cdf[(cells[c] * n + em) * n];
  int ex = int(std::upper_bound(cdf, cdf + em, u2) - cdf);
  return std::min(ex, std::max(em - 1, 0));
}

double StackResponse::elastic_albedo(int o, int wl) const {
  // f interpolated in the light cosine, integrated against 2 pi mu d mu.
  const int steps = 2000;
  Weights a;
  a.k[0] = a.k[1] = o;
  double s = 0;
  for (int j = 0; j < steps; ++j) {
    double mu = (j + 0.5) / steps;
    s += elastic_at(a, weights(mu), wl) * mu;
  }
  return 2.0 * kPi * s / steps;
}

std::string stack_response_unsupported(const StackTables& st, const MaterialTables& mt) {
  for (const auto& L : st.layers)
    for (const auto& f : L.fluors)
      if (f.texture >= 0) return "a layer fluorophore has a texture (the table holds one point's response)";
  if (st.bottom == StackBottom::kBase && !mt.fluorophores.empty()) return "the base is fluorescent";
  return {};
}

namespace {

// The walks and the elastic and fluorescent tables (what the cache keeps).
std::shared_ptr<StackResponse> fill_stack_response(const StackTables& st, const MaterialTables& mt, int n,
                                                   const StackResponseOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  auto r = std::make_shared<StackResponse>();
  r->nodes = opt.nodes;
  r->n = n;
  const DepthBins bins(st);
  const int used = opt.used_bins > 0 ? std::min(opt.used_bins, n) : n;
  const int B = bins.size(), N = opt.nodes, groups = (used + kWalkLanes - 1) / kWalkLanes;
  WalkSums sums;
  sums.fluence.assign(size_t(N) * n * B, 0.0);
  sums.exits.assign(size_t(N) * N * n, 0.0);
  ProgressBar progress("layered table" + (opt.label.empty() ? std::string() : " " + opt.label), int64_t(N) * groups);
  tbb::parallel_for(0, N * groups, [&](int job) {
    if (interrupt_requested()) return;  // Ctrl-C: the jobs left are skipped and the table dropped
    run_job(st, mt, n, bins, opt, *r, job / groups, job % groups, sums);
    progress.advance();
  });
  progress.finish();
  throw_if_interrupted("filling a layered tissue's table (nothing of it was kept)");
  r->walks = (long long)N * groups * opt.photons;
  fill_elastic(sums, opt, *r);
  fill_fluorescence(st, bins, sums, *r);
  r->build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace

StackFluence stack_fluence(const StackTables& st, const MaterialTables& mt, int n, const std::vector<double>& mu,
                           const StackResponseOptions& opt) {
  const DepthBins bins(st);
  StackFluence f;
  f.n = n;
  f.mu = mu;
  f.lo = bins.lo;
  f.hi = bins.hi;
  f.layer = bins.layer;
  const int B = bins.size(), C = int(mu.size());
  const int used = opt.used_bins > 0 ? std::min(opt.used_bins, n) : n, groups = (used + kWalkLanes - 1) / kWalkLanes;
  f.phi.assign(size_t(C) * n * B, 0.0);
  const StackWalker walker = StackWalker(st, mt, n, WalkMode::kImportance).with_similarity_after(opt.similarity_after);
  tbb::parallel_for(0, C * groups, [&](int job) {
    const int c = job / groups, group = job % groups;
    const int first_wl = group * kWalkLanes, count = std::min(kWalkLanes, n - first_wl);
    std::vector<double> tally(size_t(count) * B, 0.0);
    FluenceTally visitor{bins, tally.data()};
    for (int p = 0; p < opt.photons; ++p) {
      Rng rng(opt.seed, Rng::stream_for(uint64_t(job), uint64_t(p)));
      launch_group(st, walker, first_wl, count, rng, downward(mu[c]), visitor, [](const WalkResult&, const WalkLanes&) {});
    }
    for (int k = 0; k < count; ++k)
      for (int b = 0; b < B; ++b) f.phi[(size_t(c) * n + first_wl + k) * B + b] = tally[size_t(k) * B + b] / opt.photons;
  });
  return f;
}

std::shared_ptr<const StackResponse> build_stack_response(const StackTables& st, const MaterialTables& mt, int n,
                                                          const std::vector<std::vector<float>>& light_shapes,
                                                          const StackResponseOptions& opt) {
  std::shared_ptr<StackResponse> r;
  std::string key, warning;
  if (!opt.cache_dir.empty()) {
    key = stack_response_key(st, mt, n, opt);
    r = load_cached_stack_response(opt.cache_dir, key, opt.nodes, n, warning);
    if (r) r->from_cache = true;
  }
  if (!r) {
    r = fill_stack_response(st, mt, n, opt);
    if (!warning.empty()) r->warnings.push_back(warning);
    if (!key.empty())
      if (std::string w = store_stack_response(opt.cache_dir, key, *r); !w.empty()) r->warnings.push_back(w);
  }
  fill_sums_and_direct(light_shapes, *r);
  return r;
}

}  // namespace ofl
