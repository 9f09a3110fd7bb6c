// The position-free random walk through a layer stack (docs/layered-tissue.md).
// Only depth and direction are tracked: the light leaves where it entered, which holds when the
// pixel footprint is larger than the transport mean free path.
//
// The walk carries the wavelength lanes of a camera sample on one geometric path:
// - free flights are sampled from the mixture of the lanes' exponentials, each lane weighted by its
//   current weight (history-aware spectral tracking, Kutz et al. 2017); a lane's weight is
//   multiplied by its own transmittance over the mixture density, which is at most the number of
//   lanes, so no lane's weight can blow up;
// - at a collision each lane chooses, in proportion to its own coefficients, to scatter (HG) or to
//   be re-radiated by a fluorophore (the adjoint of absorption and re-emission: the lane moves to an
//   excitation wavelength sampled from the layer's re-emission matrix and keeps its film
//   wavelength); its weight is multiplied by mus + kappa, so absorption is never sampled, only
//   weighted. The shared new direction is drawn from a mixture of the HG lobe and the isotropic
//   phase, in proportion to the lanes that chose each, and every lane is weighted by its own phase
//   over the mixture density;
// - interfaces are crossed or reflected by Fresnel (shared by the lanes: indices do not depend on
//   wavelength); the top one may be rough. In radiance mode (camera paths) crossing from index n1 to
//   n2 multiplies the weight by (n1 / n2)^2 (radiance / n^2 is invariant); in importance mode
//   (photons from a source, the MCML comparison) it does not.
// The Visitor sees every collision with the lanes' arrival weights (for next-event estimation or
// absorption tallies), every opaque-base vertex, and every straight step (for lateral tallies).
// The walk keeps its lateral position (mm from where it started). A Lateral policy may stop a flight
// where the material under it changes (the volume walk, renderer/render/integrator/layered_bsdf.h):
// the walk then ends with WalkEnd::kRegion at that point, its lanes weighted as for a flight to a
// face, and the caller continues it in the other stack.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "renderer/render/material/albedo_matrix.h"
#include "renderer/render/material/material_tables.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/trace/sampling.h"

namespace ofl {

constexpr int kWalkLanes = 8;  // the path tracer's lanes (kLanes) share one walk

enum class WalkMode { kRadiance, kImportance };

struct WalkLanes {
  int count = kWalkLanes;  // lanes in use
  int wl[kWalkLanes] = {};
  float w[kWalkLanes] = {};
  bool fl[kWalkLanes] = {};     // the lane's light has been re-radiated (it is fluorescence)
  bool rerad[kWalkLanes] = {};  // the lane's last vertex was a re-radiation
  bool vrerad[kWalkLanes] = {}; // the lane has been re-radiated by a volume fluorophore in this walk
  float max_weight() const {
    float m = 0;
    for (int k = 0; k < count; ++k) m = std::max(m, w[k]);
    return m;
  }
};

// Texture factors of each layer's fluorophores at the surface point (1 without textures).
struct StackPointFactors {
  float f[kMaxStackLayers][kMaxLayerFluorophores];
  StackPointFactors() { std::fill(&f[0][0], &f[0][0] + kMaxStackLayers * kMaxLayerFluorophores, 1.0f); }
};

// Per-lane coefficients at the current layer (1/mm).
struct LaneCoefficients {
  float mua[kWalkLanes], mus[kWalkLanes], kappa[kWalkLanes], mut[kWalkLanes];
};

struct WalkState {
  int layer = 0;
  double depth = 0;       // mm below the top face
  glm::dvec3 d{0, 0, -1}; // travel direction, z up
  int collisions = 0;
  // True after a collision or base vertex with no interface reflection since: a path that leaves
  // the stack now could also have been made by next-event estimation from that vertex (MIS).
  bool direct = false;
  // The walk has been inside a layer that absorbs or scatters (light that leaves without having
  // done so is specular reflection off the stack's clear top, as MCML counts it).
  bool turbid = false;
  glm::dvec2 pos{0, 0};  // lateral position, mm from where the walk started
  float w_ref = 0;       // the weight Russian roulette compares with (0: the lanes' at the start)
};

enum class WalkEnd { kExitTop, kExitBottom, kAbsorbed, kTruncated, kRegion };

// No lateral structure: the stack is the same everywhere (the position-free walk).
struct NoLateral {
  static constexpr bool kActive = false;
  double limit(const WalkState&, double) { return std::numeric_limits<double>::infinity(); }
};

struct WalkResult {
  WalkEnd end = WalkEnd::kAbsorbed;
  glm::dvec3 dir{0, 0, 0};  // outside travel direction after an exit
  bool direct = false;      // see WalkState::direct
  bool turbid = false;      // see WalkState::turbid
  int collisions = 0;
};

// Walks at most this many collisions (a guard against non-absorbing stacks without an exit).
constexpr int kMaxWalkCollisions = 1 << 20;

// mua, mus and kappa of each lane in layer `l` with the point's fluorophore factors.
inline void lane_coefficients(const StackLayerTables& L, const float* fac, const WalkLanes& lanes, bool emit,
                              LaneCoefficients& c) {
  for (int k = 0; k < lanes.count; ++k) {
    int wl = lanes.wl[k];
    float mua = L.mua[wl], kappa = 0;
    for (size_t j = 0; j < L.fluors.size(); ++j) {
      mua += fac[j] * L.fluors[j].absorb[wl];
      if (emit) kappa += fac[j] * L.fluors[j].row_sum[wl];
    }
    c.mua[k] = mua;
    c.mus[k] = L.mus[wl];
    c.kappa[k] = kappa;
    c.mut[k] = mua + L.mus[wl];
  }
}

// Henyey-Greenstein phase function of the cosine between the travel directions before and after.
inline double hg_phase(double g, double cos_t) {
  double d = 1.0 + g * g - 2.0 * g * cos_t;
  return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

// A travel direction after HG scattering of `d` (exactly distributed as hg_phase).
inline glm::dvec3 sample_hg(double g, const glm::dvec3& d, double u1, double u2) {
  double c;
  if (std::abs(g) < 1e-4) {
    c = 1.0 - 2.0 * u1;
  } else {
    double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
    c = (1.0 + g * g - s * s) / (2.0 * g);
  }
  c = std::clamp(c, -1.0, 1.0);
  double sn = std::sqrt(std::max(0.0, 1.0 - c * c)), phi = 2.0 * kPi * u2;
  Frame f(d);
  return f.to_world(glm::dvec3(sn * std::cos(phi), sn * std::sin(phi), c));
}

// An excitation bin for a lane at emission bin `em` re-radiated in layer L: fluorophore in
// proportion to factor * kappa_j(em), then the bin from its row CDF.
inline int sample_layer_excitation(const StackLayerTables& L, const float* fac, int em, float u, int n) {
  float total = 0;
  for (size_t j = 0; j < L.fluors.size(); ++j) total += fac[j] * L.fluors[j].row_sum[em];
  float target = u * total;
  size_t j = 0;
  for (; j + 1 < L.fluors.size(); ++j) {
    float wj = fac[j] * L.fluors[j].row_sum[em];
    if (target < wj) break;
    target -= wj;
  }
  float wj = fac[j] * L.fluors[j].row_sum[em];
  float uu = wj > 0 ? std::clamp(target / wj, 0.0f, 0.99999994f) : u;
  const float* cdf = L.fluors[j].row_cdf.data() + size_t(em) * n;
  int ex = int(std::upper_bound(cdf, cdf + em, uu) - cdf);
  return std::min(ex, std::max(em - 1, 0));
}

class StackWalker {
 public:
  StackWalker(const StackTables& st, const MaterialTables& mt, int n, WalkMode mode)
      : st_(st), mt_(mt), n_(n), mode_(mode) {}

  // Walks from `s` (inside layer s.layer, travelling along s.d) until the path leaves the stack,
  // is absorbed (all weights zero or Russian roulette) or hits the collision guard.
  template <class Visitor>
  WalkResult walk(WalkState& s, WalkLanes& lanes, const StackPointFactors& fac, Rng& rng, Visitor& v) const {
    NoLateral none;
    return walk(s, lanes, fac, rng, v, none);
  }
  // The same, stopping (WalkEnd::kRegion) where lat.limit(s, t) says, for a flight of length t from
  // s, that the material under it changes at a distance below t.
  template <class Visitor, class Lateral>
  WalkResult walk(WalkState& s, WalkLanes& lanes, const StackPointFactors& fac, Rng& rng, Visitor& v, Lateral& lat) const;
  const StackTables& stack() const { return st_; }

  // Crosses an interface from index n1 into n2: the radiance-mode weight factor.
  double crossing_factor(double n1, double n2) const { return mode_ == WalkMode::kRadiance ? (n1 / n2) * (n1 / n2) : 1.0; }

  // A radiance-mode walker whose lanes are never re-radiated (fluorophores only absorb): the
  // scattered-excitation sub-walks of next-event estimation (layered_bsdf.cpp).
  StackWalker without_reradiation() const {
    StackWalker w = *this;
    w.reradiate_ = false;
    return w;
  }
  // A walker that, after `collisions` collisions (0: never), scatters by the similarity relation:
  // mus -> mus (1 - g) and g -> 0 (same transport mean free path, isotropic). A direction has no
  // memory left after a few times 1 / (1 - g) collisions, so quantities averaged over directions
  // deep in the walk (the table's depth-resolved fluence and exits) barely change, while a walk in
  // a strongly forward-scattering stroma takes about (1 - g) as many collisions. For the table's
  // fill only (stack_response.cpp); the render-time walk and the MCML cases use the exact phase.
  StackWalker with_similarity_after(int collisions) const {
    StackWalker w = *this;
    w.similarity_after_ = collisions;
    return w;
  }

 private:
  enum class Boundary { kContinue, kExitTop, kExitBottom, kLost };
  Boundary cross(WalkState& s, WalkLanes& lanes, Rng& rng, glm::dvec3* exit_dir) const;
  template <class Visitor>
  bool base_vertex(WalkState& s, WalkLanes& lanes, Rng& rng, Visitor& v) const;
  void scatter_lanes(WalkState& s, WalkLanes& lanes, const LaneCoefficients& c, const float* fac, double g, Rng& rng) const;
  bool roulette(WalkLanes& lanes, float w_ref, Rng& rng) const;
  // A flight that reaches distance t without a collision: each lane weighted by its transmittance
  // over the probability that the mixture's flight is longer than t. False when no lane can get there.
  bool transmit(WalkLanes& lanes, const LaneCoefficients& c, float wsum, double t) const {
    double p = 0;
    float tr[kWalkLanes];
    for (int k = 0; k < lanes.count; ++k) {
      tr[k] = std::exp(-c.mut[k] * float(t));
      p += lanes.w[k] / wsum * tr[k];
    }
    if (!(p > 0)) return false;
    for (int k = 0; k < lanes.count; ++k) lanes.w[k] = float(lanes.w[k] * tr[k] / p);
    return true;
  }
  // The same, and s moved there.
  template <class Visitor>
  bool flight_to(WalkState& s, WalkLanes& lanes, const LaneCoefficients& c, float wsum, double t, Visitor& v) const;

  const StackTables& st_;
  const MaterialTables& mt_;
  int n_;
  WalkMode mode_;
  bool reradiate_ = true;
  int similarity_after_ = 0;
};

template <class Visitor, class Lateral>
WalkResult StackWalker::walk(WalkState& s, WalkLanes& lanes, const StackPointFactors& fac, Rng& rng, Visitor& v,
                             Lateral& lat) const {
  WalkResult r;
  if (!(s.w_ref > 0)) s.w_ref = std::max(lanes.max_weight(), 1e-30f);
  const float w_ref = s.w_ref;
  const bool emit = mode_ == WalkMode::kRadiance && reradiate_;
  LaneCoefficients c;
  for (;;) {
    const StackLayerTables& L = st_.layers[s.layer];
    const float* f = fac.f[s.layer];
    double to_face = s.d.z < 0 ? (L.bottom - s.depth) / -s.d.z : s.d.z > 0 ? (s.depth - L.top) / s.d.z
                                                                           : std::numeric_limits<double>::infinity();
    double t = std::numeric_limits<double>::infinity();
    if (!L.clear) {
      s.turbid = true;
      lane_coefficients(L, f, lanes, emit, c);
      const bool similar = similarity_after_ > 0 && s.collisions >= similarity_after_ && L.g != 0;
      if (similar)
        for (int k = 0; k < lanes.count; ++k) {
          const float forward = c.mus[k] * float(L.g);
          c.mus[k] -= forward;
          c.mut[k] -= forward;
        }
      // Pick a lane in proportion to its weight and sample its exponential.
      float wsum = 0;
      for (int k = 0; k < lanes.count; ++k) wsum += lanes.w[k];
      if (!(wsum > 0)) { r.end = WalkEnd::kAbsorbed; break; }
      float u = rng.next_float() * wsum;
      int h = 0;
      for (; h + 1 < lanes.count; ++h) {
        if (u < lanes.w[h]) break;
        u -= lanes.w[h];
      }
      if (c.mut[h] > 0) t = -std::log(1.0 - rng.next_double()) / c.mut[h];
      if constexpr (Lateral::kActive) {
        const double tb = lat.limit(s, std::min(t, to_face));
        if (tb < std::min(t, to_face)) {
          if (!flight_to(s, lanes, c, wsum, tb, v)) { r.end = WalkEnd::kAbsorbed; break; }
          r.end = WalkEnd::kRegion;
          break;
        }
      }
      if (t < to_face) {
        double p = 0;
        float tr[kWalkLanes];
        for (int k = 0; k < lanes.count; ++k) {
          tr[k] = std::exp(-c.mut[k] * float(t));
          p += lanes.w[k] / wsum * c.mut[k] * tr[k];
        }
        for (int k = 0; k < lanes.count; ++k) lanes.w[k] = float(lanes.w[k] * tr[k] / p);
        v.moved(s.d, t);
        s.pos += t * glm::dvec2(s.d.x, s.d.y);
        s.depth -= t * s.d.z;
        s.depth = std::clamp(s.depth, L.top, L.bottom);
        ++s.collisions;
        v.collision(s, c, lanes);
        scatter_lanes(s, lanes, c, f, similar ? 0.0 : L.g, rng);
        s.direct = true;
        if (s.collisions >= kMaxWalkCollisions) { r.end = WalkEnd::kTruncated; break; }
        if (!roulette(lanes, w_ref, rng)) { r.end = WalkEnd::kAbsorbed; break; }
        continue;
      }
      if (!transmit(lanes, c, wsum, to_face)) { r.end = WalkEnd::kAbsorbed; break; }
    } else if constexpr (Lateral::kActive) {
      // A clear layer: straight to its face unless the material under the flight changes first.
      const double tb = lat.limit(s, to_face);
      if (tb < to_face) {
        v.moved(s.d, tb);
        s.pos += tb * glm::dvec2(s.d.x, s.d.y);
        s.depth = std::clamp(s.depth - tb * s.d.z, L.top, L.bottom);
        r.end = WalkEnd::kRegion;
        break;
      }
    }
    if (!std::isfinite(to_face)) { r.end = WalkEnd::kAbsorbed; break; }  // horizontal in a semi-infinite layer
    v.moved(s.d, to_face);
    s.pos += to_face * glm::dvec2(s.d.x, s.d.y);
    s.depth = s.d.z < 0 ? L.bottom : L.top;
    glm::dvec3 out;
    if (s.d.z < 0 && s.layer + 1 == int(st_.layers.size()) && st_.bottom == StackBottom::kBase) {
      if (!base_vertex(s, lanes, rng, v)) { r.end = WalkEnd::kAbsorbed; break; }
      if (!roulette(lanes, w_ref, rng)) { r.end = WalkEnd::kAbsorbed; break; }
      continue;
    }
    Boundary b = cross(s, lanes, rng, &out);
    if (b == Boundary::kContinue) continue;
    if (b == Boundary::kLost) { r.end = WalkEnd::kAbsorbed; break; }
    r.end = b == Boundary::kExitTop ? WalkEnd::kExitTop : WalkEnd::kExitBottom;
    r.dir = out;
    break;
  }
  r.direct = s.direct;
  r.turbid = s.turbid;
  r.collisions = s.collisions;
  return r;
}

template <class Visitor>
bool StackWalker::flight_to(WalkState& s, WalkLanes& lanes, const LaneCoefficients& c, float wsum, double t,
                            Visitor& v) const {
  if (!transmit(lanes, c, wsum, t)) return false;
  const StackLayerTables& L = st_.layers[s.layer];
  v.moved(s.d, t);
  s.pos += t * glm::dvec2(s.d.x, s.d.y);
  s.depth = std::clamp(s.depth - t * s.d.z, L.top, L.bottom);
  return true;
}

template <class Visitor>
bool StackWalker::base_vertex(WalkState& s, WalkLanes& lanes, Rng& rng, Visitor& v) const {
  v.base_vertex(s, lanes);
  LocalMaterial lm{&mt_};
  lm.nf = std::min<int>(int(mt_.fluorophores.size()), kMaxFluorophoresPerMaterial);
  for (int j = 0; j < lm.nf; ++j) lm.conc[j] = mt_.fluorophores[j].concentration;
  bool any = false;
  for (int k = 0; k < lanes.count; ++k) {
    if (lanes.w[k] == 0) continue;
    bool rr = false;
    float a = mode_ == WalkMode::kRadiance ? albedo_step(lm, lanes.wl[k], rng, n_, &rr)
                                           : mt_.reflectance[lanes.wl[k]];
    lanes.w[k] *= a;
    lanes.rerad[k] = rr;
    if (rr) lanes.fl[k] = true;
    any = any || lanes.w[k] > 0;
  }
  glm::dvec3 d = sample_cosine_hemisphere(rng.next_double(), rng.next_double());
  s.d = d;
  s.direct = true;
  ++s.collisions;
  return any;
}

}  // namespace ofl
