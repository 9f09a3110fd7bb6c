// The lateral profiles of a layer stack (see stack_profiles.h).
#include "renderer/render/spatial/stack_profiles.h"

#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>

#include "renderer/core/files/hash.h"
#include "renderer/core/process/progress.h"
#include "renderer/render/stack/stack_fill.h"
#include "renderer/render/stack/stack_response_cache.h"

namespace ofl {

const std::vector<double>& leg_depth_edges() {
  static const std::vector<double> e = {0.0,  0.01, 0.025, 0.05, 0.075, 0.1, 0.125, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45,
                                        0.5,  0.6,  0.7,   0.85, 1.0,   1.25, 1.5,  2.0,  2.5, 3.0,  4.0, 5.0,  7.0, kDepthCap};
  return e;
}

StackProfiles::CosineWeights StackProfiles::weights(double mu) const {
  CosineWeights w;
  const int C = int(cosines.size());
  if (C == 0 || mu >= cosines.front()) return w;
  if (mu <= cosines.back()) {
    w.c[0] = w.c[1] = C - 1;
    return w;
  }
  int k = 0;
  while (k + 2 < C && mu < cosines[k + 1]) ++k;
  const double t = (cosines[k] - mu) / (cosines[k] - cosines[k + 1]);
  w.c[0] = k;
  w.c[1] = k + 1;
  w.w[0] = 1.0 - t;
  w.w[1] = t;
  return w;
}

namespace {

int slice_of(double depth) {
  const auto& e = leg_depth_edges();
  if (!(depth >= 0) || depth >= e.back()) return -1;
  return int(std::upper_bound(e.begin(), e.end(), depth) - e.begin()) - 1;
}

// The tallies of one (cosine, wavelength group) job: the walk's lateral position, and per lane the
// collisions (fluence) by fine depth bin and by (depth slice, ring), and the exits by ring.
struct LateralTally {
  const DepthBins& fine;
  const RadialRings& legs;
  const RadialRings& exits_rings;
  int lanes, Z;
  std::vector<double> leg, fine_t, exits, rd;
  double x = 0, y = 0;

  LateralTally(const DepthBins& f, const RadialRings& l, const RadialRings& e, int count)
      : fine(f), legs(l), exits_rings(e), lanes(count), Z(int(leg_depth_edges().size()) - 1),
        leg(size_t(count) * Z * l.rings, 0.0), fine_t(size_t(count) * f.size(), 0.0),
        exits(size_t(count) * e.rings, 0.0), rd(count, 0.0) {}

  void moved(const glm::dvec3& d, double t) {
    x += d.x * t;
    y += d.y * t;
  }
  void collision(const WalkState& s, const LaneCoefficients&, const WalkLanes& w) {
    const int b = fine.find(s.layer, s.depth);
    if (b >= 0)
      for (int k = 0; k < lanes; ++k) fine_t[size_t(k) * fine.size() + b] += w.w[k];
    const int z = slice_of(s.depth), j = legs.ring_of(std::hypot(x, y));
    if (z < 0 || j < 0) return;
    for (int k = 0; k < lanes; ++k) leg[(size_t(k) * Z + z) * legs.rings + j] += w.w[k];
  }
  void base_vertex(const WalkState&, const WalkLanes&) {}
  void exited(const WalkLanes& w) {
    const int j = exits_rings.ring_of(std::hypot(x, y));
    for (int k = 0; k < lanes; ++k) {
      rd[k] += w.w[k];
      if (j >= 0) exits[size_t(k) * exits_rings.rings + j] += w.w[k];
    }
  }
};

void run_profile_job(const StackTables& st, const MaterialTables& mt, int n, const DepthBins& fine,
                     const StackProfileOptions& opt, int c, int group, StackProfiles& p) {
  const int first_wl = group * kWalkLanes, count = std::min(kWalkLanes, n - first_wl);
  LateralTally t(fine, p.leg_rings, p.elastic_rings, count);
  const StackWalker walker = StackWalker(st, mt, n, WalkMode::kImportance).with_similarity_after(opt.similarity_after);
  const uint64_t job = uint64_t(c) * 4096 + uint64_t(group);
  const glm::dvec3 down = downward(opt.cosines[c]);
  for (int i = 0; i < opt.photons; ++i) {
    Rng rng(opt.seed, Rng::stream_for(job, uint64_t(i)));
    t.x = t.y = 0;
    launch_group(st, walker, first_wl, count, rng, down, t, [&](const WalkResult& r, const WalkLanes& w) {
      if (r.turbid || opt.clear_exits) t.exited(w);
    });
  }
  const double inv = 1.0 / opt.photons;
  const int Z = p.slices(), RL = p.leg_rings.rings, RE = p.elastic_rings.rings, B = fine.size();
  for (int k = 0; k < count; ++k) {
    const int wl = first_wl + k;
    const size_t cw = size_t(c) * n + wl;
    const double kept = radial::normalise(RE, &t.exits[size_t(k) * RE], &p.elastic_mass[cw * RE], &p.elastic_cdf[cw * RE]);
    p.rd[cw] = float(t.rd[k] * inv);
    p.kept[cw] = float(t.rd[k] > 0 ? kept / t.rd[k] : 1.0);
    for (int z = 0; z < Z; ++z) {
      const size_t at = p.leg_index(c, wl, z);
      const double total = radial::normalise(RL, &t.leg[(size_t(k) * Z + z) * RL], &p.leg_mass[at], &p.leg_cdf[at]);
      p.leg_fluence[cw * Z + z] = float(total * inv);
    }
    for (int b = 0; b < B; ++b) p.fine_fluence[cw * B + b] = float(t.fine_t[size_t(k) * B + b] * inv);
  }
}

std::shared_ptr<StackProfiles> empty_profiles(const StackTables& st, int n, const StackProfileOptions& opt) {
  auto p = std::make_shared<StackProfiles>();
  p->n = n;
  p->cosines = opt.cosines;
  p->elastic_rings = opt.elastic_rings;
  p->leg_rings = opt.leg_rings;
  p->depth_edges = leg_depth_edges();
  p->fine_bins = DepthBins(st).size();
  const size_t C = opt.cosines.size(), cw = C * n, Z = p->slices();
  p->elastic_mass.assign(cw * opt.elastic_rings.rings, 0.0f);
  p->elastic_cdf.assign(cw * opt.elastic_rings.rings, 1.0f);
  p->rd.assign(cw, 0.0f);
  p->kept.assign(cw, 1.0f);
  p->leg_mass.assign(cw * Z * opt.leg_rings.rings, 0.0f);
  p->leg_cdf.assign(cw * Z * opt.leg_rings.rings, 1.0f);
  p->leg_fluence.assign(cw * Z, 0.0f);
  p->fine_fluence.assign(cw * p->fine_bins, 0.0f);
  return p;
}

std::shared_ptr<StackProfiles> fill_stack_profiles(const StackTables& st, const MaterialTables& mt, int n,
                                                   const StackProfileOptions& opt) {
  auto t0 = std::chrono::steady_clock::now();
  auto p = empty_profiles(st, n, opt);
  const DepthBins fine(st);
  const int used = opt.used_bins > 0 ? std::min(opt.used_bins, n) : n;
  const int C = int(opt.cosines.size()), groups = (used + kWalkLanes - 1) / kWalkLanes;
  ProgressBar progress("layered profiles" + (opt.label.empty() ? std::string() : " " + opt.label), int64_t(C) * groups);
  tbb::parallel_for(0, C * groups, [&](int job) {
    run_profile_job(st, mt, n, fine, opt, job / groups, job % groups, *p);
    progress.advance();
  });
  progress.finish();
  p->walks = (long long)C * groups * opt.photons;
  p->build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return p;
}

// The arrays an entry of the cache holds, in order.
std::vector<std::vector<float>*> cached_arrays(StackProfiles& p) {
  return {&p.elastic_mass, &p.elastic_cdf, &p.rd, &p.kept, &p.leg_mass, &p.leg_cdf, &p.leg_fluence, &p.fine_fluence};
}

}  // namespace

std::string stack_profile_key(const StackTables& st, const MaterialTables& mt, int n, const StackProfileOptions& opt) {
  Fnv128 f;
  f.text("oralfluor stack profiles");
  f.text(stack_content_key(st, mt, n));
  f.values(opt.cosines);
  f.value(opt.photons);
  f.value(opt.similarity_after);
  f.value(opt.elastic_rings.r_max);
  f.value(opt.elastic_rings.rings);
  f.value(opt.leg_rings.r_max);
  f.value(opt.leg_rings.rings);
  f.values(leg_depth_edges());
  f.value(opt.seed);
  f.value(opt.clear_exits);
  f.value(opt.used_bins > 0 ? std::min(opt.used_bins, n) : n);
  return f.hex();
}

std::shared_ptr<const StackProfiles> build_stack_profiles(const StackTables& st, const MaterialTables& mt, int n,
                                                          const StackProfileOptions& opt) {
  std::string key, warning;
  if (!opt.cache_dir.empty()) {
    key = stack_profile_key(st, mt, n, opt);
    auto p = empty_profiles(st, n, opt);
    if (load_float_entry(opt.cache_dir, key, kProfileEntry, cached_arrays(*p), p->walks, p->build_seconds, warning)) {
      p->from_cache = true;
      return p;
    }
  }
  auto p = fill_stack_profiles(st, mt, n, opt);
  if (!warning.empty()) p->warnings.push_back(warning);
  if (!key.empty()) {
    const auto arrays = cached_arrays(*p);
    const std::vector<const std::vector<float>*> out(arrays.begin(), arrays.end());
    if (std::string w = store_float_entry(opt.cache_dir, key, kProfileEntry, out, p->walks, p->build_seconds); !w.empty())
      p->warnings.push_back(w);
  }
  return p;
}

}  // namespace ofl
