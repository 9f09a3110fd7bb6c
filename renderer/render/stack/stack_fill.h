// What the fills of a layer stack's tables share (the position-free table,
// renderer/render/stack/stack_response.cpp, and the lateral profiles, renderer/render/spatial/
// stack_profiles.cpp): the depth bins fluence is tallied in, and photons launched into the stack
// through its top interface as a source (importance mode) would send them.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>

#include "renderer/render/stack/stack_walk.h"

namespace ofl {

// Depth bins of the fluence tallies: per layer, widths growing geometrically from the layer's top
// (where the unscattered LED light decays fastest), capped; a semi-infinite layer is followed to
// kDepthCap below its top (deeper collisions are not tallied: nothing from there returns).
inline constexpr double kFirstBin = 0.003, kGrowth = 1.15, kWidestBin = 0.2, kDepthCap = 10.0;  // mm

struct DepthBins {
  std::vector<double> lo, hi;
  std::vector<int> layer;
  std::vector<int> first, end;  // per layer: its bins [first, end)

  explicit DepthBins(const StackTables& st) {
    for (int l = 0; l < int(st.layers.size()); ++l) {
      const StackLayerTables& L = st.layers[l];
      first.push_back(int(lo.size()));
      const double bottom = std::min(L.bottom, L.top + kDepthCap);
      if (L.clear) {
        add(L.top, bottom, l);
      } else {
        double z = L.top, h = kFirstBin;
        while (z < bottom) {
          double e = std::min(z + h, bottom);
          if (bottom - e < 0.25 * h) e = bottom;  // no sliver at the bottom
          add(z, e, l);
          z = e;
          h = std::min(h * kGrowth, kWidestBin);
        }
      }
      end.push_back(int(lo.size()));
    }
  }
  void add(double a, double b, int l) {
    lo.push_back(a);
    hi.push_back(b);
    layer.push_back(l);
  }
  int size() const { return int(lo.size()); }
  // The bin of depth z in layer l, or -1 below the cap.
  int find(int l, double z) const {
    auto b = hi.begin() + first[l], e = hi.begin() + end[l];
    auto it = std::upper_bound(b, e, z);
    if (it == e) return z <= hi[end[l] - 1] ? end[l] - 1 : -1;
    return int(it - hi.begin());
  }
};

// Per layer, sigma_l(em <- ex) summed over its fluorophores ([em * n + ex], 1/mm, bin width included).
inline std::vector<std::vector<float>> layer_emission(const StackTables& st, int n) {
  std::vector<std::vector<float>> out;
  for (const StackLayerTables& L : st.layers) {
    std::vector<float> s;
    for (const auto& f : L.fluors) {
      if (f.emit.empty()) continue;
      if (s.empty()) s.assign(size_t(n) * n, 0.0f);
      for (size_t j = 0; j < s.size(); ++j) s[j] += f.emit[j];
    }
    out.push_back(std::move(s));
  }
  return out;
}

// A downward travel direction of cosine mu (azimuth 0).
inline glm::dvec3 downward(double mu) { return {-std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, -mu}; }

// Photons of one wavelength group (bins first_wl .. first_wl + count - 1, one lane each) entering
// through the top from `down`; `visitor` sees their collisions (StackWalker's Visitor) and
// `exited(result, lanes)` every walk that leaves through the top. Light the top reflects is not
// walked (the tables keep the top's specular lobe in closed form).
template <class Visitor, class Exit>
void launch_group(const StackTables& st, const StackWalker& walker, int first_wl, int count, Rng& rng,
                  const glm::dvec3& down, Visitor& visitor, Exit exited) {
  InterfaceEvent e = st.top.scatter(down, rng);
  if (e.weight <= 0 || !e.transmitted) return;
  WalkLanes lanes;
  lanes.count = count;
  for (int k = 0; k < count; ++k) {
    lanes.wl[k] = first_wl + k;
    lanes.w[k] = float(e.weight);
  }
  WalkState s;
  s.d = e.dir;
  const StackPointFactors fac;
  WalkResult res = walker.walk(s, lanes, fac, rng, visitor);
  if (res.end == WalkEnd::kExitTop && res.dir.z > 0) exited(res, lanes);
}

}  // namespace ofl
