// Layered tissue at a path vertex (see layered_bsdf.h).
#include <array>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>

#include "renderer/render/integrator/layered_bsdf.h"

#include "renderer/render/stack/stack_response.h"
#include "renderer/render/stack/stack_walk.h"

namespace ofl {
namespace {

// The direction light from the LED travels in each layer, and what it loses on the way there.
struct StackConnection {
  bool valid = false;
  double top_weight = 0;                    // power transmitted by the top interface
  glm::dvec3 dir[kMaxStackLayers];          // travel direction in layer j (z < 0)
  double mu[kMaxStackLayers] = {};          // -dir.z
  double fresnel_t[kMaxStackLayers] = {};   // product of internal interface transmittances above layer j
  double len[kMaxStackLayers] = {};         // path length across layer j (finite layers)
  int reach = -1;                           // deepest layer the direction reaches

  StackConnection(const StackTables& st, const glm::dvec3& wi, Rng& rng) {
    const double n0 = st.layers[0].ior;
    glm::dvec3 d;
    if (st.top.smooth()) {
      top_weight = 1.0 - fresnel_dielectric(wi.z, n0 / st.ambient_ior);
      if (!refract_smooth(-wi, st.ambient_ior / n0, &d)) return;
    } else {
      InterfaceEvent e = st.top.transmit(-wi, rng.next_double(), rng.next_double());
      top_weight = e.weight;
      d = e.dir;
    }
    if (!(top_weight > 0) || d.z >= 0) return;
    valid = true;
    double ft = 1.0;
    for (int j = 0; j < int(st.layers.size()); ++j) {
      const StackLayerTables& L = st.layers[j];
      if (j > 0) {
        double n1 = st.layers[j - 1].ior, n2 = L.ior;
        if (n1 != n2) {
          ft *= 1.0 - fresnel_dielectric(-d.z, n2 / n1);
          if (!refract_smooth(d, n1 / n2, &d)) break;
        }
      }
      dir[j] = d;
      mu[j] = -d.z;
      fresnel_t[j] = ft;
      len[j] = std::isfinite(L.bottom) ? (L.bottom - L.top) / mu[j] : 0.0;
      reach = j;
    }
  }
};

// Total attenuation coefficient at bin `wl` in layer L with the point's fluorophore factors.
inline float layer_mut(const StackLayerTables& L, const float* fac, int wl) {
  float m = L.mua[wl] + L.mus[wl];
  for (size_t j = 0; j < L.fluors.size(); ++j) m += fac[j] * L.fluors[j].absorb[wl];
  return m;
}

// Scattered-excitation sub-walks: launched at a collision of the camera walk with probability
// kSubwalkRate exp(-D), D the LED light's diffusion optical depth down to the collision (no less
// than kSubwalkMinRate, so that every depth stays sampled), the estimate divided by it. Measured on
// lateral_tongue under 405 nm (time x variance of the fluorescence): rate 1 / floor 0.001 is 1.6x
// more efficient than 0.5 / 0.02; a higher rate costs more than it saves.
constexpr double kSubwalkRate = 1.0;
constexpr double kSubwalkMinRate = 0.001;
// Unscattered LED transmittance below which direct excitation is evaluated only sometimes.
constexpr double kDirectFloor = 1e-3;

// Runs the scattered-excitation sub-walks of a volume walk (VolumeWalk below): from `s`, in the
// material of the volume walk's slot `slot`, crossing into other materials as the camera walk does.
class ExcitationWalks {
 public:
  virtual void sub_walk(WalkState& s, WalkLanes& lanes, double* acc, int slot) = 0;

 protected:
  ~ExcitationWalks() = default;
};

// Next-event estimation at every vertex of the walk, gathered into the camera path's lanes.
//
// Volume fluorescence excited by LED light is estimated at every collision of a lane (at its
// current wavelength, as the emission wavelength) in two parts, so that it never hinges on the rare
// event of the walk choosing to re-radiate (probability kappa / (mus + kappa) per collision, about
// 1e-3 in oral tissue):
// - unscattered LED light reaching the point: summed deterministically over the LED's bins;
// - LED light that scattered in the stack first: a sub-walk from the point in a uniform direction
//   (the adjoint of isotropic emission) carries excitation lanes drawn from the LED spectrum times
//   the fluorophores' absorption, without re-radiation, with next-event estimation at its
//   collisions. A lane that the walk did re-radiate in a volume therefore skips next-event
//   estimation for the rest of the walk (the sub-walks cover those paths); its exits still count.
class WalkNee {
 public:
  WalkNee(const StackTables& st, const MaterialTables& mt, const StackPointFactors& fac, const LightSample& ls,
          const StackConnection& conn, const float* shape, double mis, int n, PathLanes& p,
          const StackWalker* sub_walker, Rng* rng)
      : st_(st), mt_(mt), fac_(fac), ls_(ls), c_(conn), shape_(shape), mis_(mis), n_(n), p_(&p),
        sub_walker_(sub_walker), rng_(rng), tex_(st.led_support[ls.group].size()) {}
  // A sub-walk's visitor: next-event estimation of scattered light into `acc`, nothing else.
  WalkNee(const StackTables& st, const MaterialTables& mt, const StackPointFactors& fac, const LightSample& ls,
          const StackConnection& conn, const float* shape, double mis, int n, double* acc, Rng& rng)
      : st_(st), mt_(mt), fac_(fac), ls_(ls), c_(conn), shape_(shape), mis_(mis), n_(n), acc_(acc), rng_(&rng) {}

  // In a volume walk: the scattered-excitation sub-walks go sideways too, through `walks`, starting
  // in the material of its slot `slot` (this visitor's).
  void run_subwalks_in(ExcitationWalks* walks, int slot) {
    volume_ = walks;
    slot_ = slot;
  }

  void moved(const glm::dvec3&, double) {}

  void collision(const WalkState& s, const LaneCoefficients& c, const WalkLanes& lanes) {
    const int l = s.layer;
    if (l > c_.reach) return;
    scattered_light(s, c, lanes);
    if (acc_ != nullptr) return;  // a sub-walk: scattered excitation light only
    const StackLayerTables& L = st_.layers[l];
    if (L.fluors.empty() || L.fluors.front().emit.empty()) return;
    direct_excitation(s, lanes);
    if (sub_walker_ == nullptr) return;
    const double rate = subwalk_rate(s);
    if (rng_->next_double() < rate) scattered_excitation(s, lanes, rate);
  }

  void base_vertex(const WalkState& s, const WalkLanes& lanes) {
    const int l = int(st_.layers.size()) - 1;
    if (l > c_.reach) return;
    const double common = c_.fresnel_t[l] * c_.top_weight * ls_.g / kPi;
    int max_wl = 0;
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0 || lanes.vrerad[k]) continue;
      max_wl = std::max(max_wl, lanes.wl[k]);
      const int em = lanes.wl[k];
      add(k, lanes.w[k] * mt_.reflectance[em] * std::exp(-through(em)) * shape_[em] * mis_ * common, lanes.fl[k]);
    }
    if (mt_.fluorophores.empty() || acc_ != nullptr) return;
    // The base's fluorophores excited by LED light that crossed every layer (summed over its bins).
    const auto& support = st_.led_support[ls_.group];
    double* tex = tex_.data();
    int m = 0;
    for (const auto& [ex, S] : support) {
      if (ex >= max_wl) break;
      tex[m++] = std::exp(-through(ex)) * S;
    }
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0 || lanes.vrerad[k]) continue;
      const int em = lanes.wl[k];
      double fluo = 0;
      for (const auto& f : mt_.fluorophores) {
        const float* row = f.phi.data() + size_t(em) * n_;
        double sf = 0;
        for (int i = 0; i < m && support[i].first < em; ++i) sf += row[support[i].first] * tex[i];
        fluo += f.concentration * sf;
      }
      if (fluo > 0) add(k, lanes.w[k] * fluo * common, true);
    }
  }

 private:
  // LED light scattered toward the camera path at this collision.
  void scattered_light(const WalkState& s, const LaneCoefficients& c, const WalkLanes& lanes) {
    const int l = s.layer;
    const StackLayerTables& L = st_.layers[l];
    const double dz = s.depth - L.top;
    const double common = c_.fresnel_t[l] * c_.top_weight / c_.mu[l] * ls_.g;
    const double hg = hg_phase(L.g, glm::dot(c_.dir[l], -s.d));
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0 || lanes.vrerad[k] || shape_[lanes.wl[k]] == 0) continue;
      double tau = above(l, lanes.wl[k]) + double(c.mut[k]) * dz / c_.mu[l];
      add(k, lanes.w[k] * c.mus[k] * hg * std::exp(-tau) * shape_[lanes.wl[k]] * common * mis_, lanes.fl[k]);
    }
  }

  // Unscattered LED light reaching this point, absorbed and re-emitted at each lane's wavelength;
  // summed over the LED's bins.
  void direct_excitation(const WalkState& s, const WalkLanes& lanes) {
    const int l = s.layer;
    const StackLayerTables& L = st_.layers[l];
    const double dz = s.depth - L.top;
    const auto& support = st_.led_support[ls_.group];
    const int max_wl = max_lane_wl(lanes);
    double* tex = tex_.data();
    int m = 0;
    double t_max = 0;
    for (const auto& [ex, S] : support) {
      if (ex >= max_wl) break;
      double tau = above(l, ex) + double(layer_mut(L, fac_.f[l], ex)) * dz / c_.mu[l];
      t_max = std::max(t_max, std::exp(-tau));
      tex[m++] = std::exp(-tau) * S;
    }
    if (m == 0 || t_max == 0) return;
    // Deep below the surface hardly any unscattered LED light is left: evaluate there with
    // probability t_max / kDirectFloor (Russian roulette, unbiased).
    double keep = std::min(1.0, t_max / kDirectFloor);
    if (keep < 1.0 && rng_->next_double() >= keep) return;
    const double iso = c_.fresnel_t[l] * c_.top_weight / c_.mu[l] * ls_.g / (4.0 * kPi) / keep;
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0) continue;
      const int em = lanes.wl[k];
      double sum = 0;
      for (size_t j = 0; j < L.fluors.size(); ++j) {
        const float* row = L.fluors[j].emit.data() + size_t(em) * n_;
        double sj = 0;
        for (int i = 0; i < m && support[i].first < em; ++i) sj += row[support[i].first] * tex[i];
        sum += fac_.f[l][j] * sj;
      }
      if (sum > 0) add(k, lanes.w[k] * sum * iso, true);
    }
  }

  // LED light that scattered before reaching this point, absorbed and re-emitted at each lane's
  // wavelength: one sub-walk with excitation lanes stratified over the LED's bins in proportion to
  // their photon shape times the layer's fluorophore absorption.
  double subwalk_rate(const WalkState& s) const {
    const auto& mu_eff = st_.led_mu_eff[ls_.group];
    double D = 0;
    for (int i = 0; i < s.layer; ++i) D += mu_eff[i] * (st_.layers[i].bottom - st_.layers[i].top);
    D += mu_eff[s.layer] * (s.depth - st_.layers[s.layer].top);
    return std::max(kSubwalkMinRate, kSubwalkRate * std::exp(-D));
  }

  void scattered_excitation(const WalkState& s, const WalkLanes& lanes, double rate) {
    const int l = s.layer;
    const StackLayerTables& L = st_.layers[l];
    const float* f = fac_.f[l];
    const auto& support = st_.led_support[ls_.group];
    const int max_wl = max_lane_wl(lanes);
    double* q = tex_.data();
    double total = 0;
    int m = 0;
    for (const auto& [ex, S] : support) {
      if (ex >= max_wl) break;
      double a = 0;
      for (size_t j = 0; j < L.fluors.size(); ++j) a += f[j] * L.fluors[j].absorb[ex];
      q[m++] = S * a;
      total += S * a;
    }
    if (!(total > 0)) return;
    WalkLanes sub;
    double prob[kWalkLanes];
    for (int i = 0; i < kWalkLanes; ++i) {
      double target = (i + rng_->next_double()) / kWalkLanes * total;
      int b = 0;
      for (; b + 1 < m && target >= q[b]; ++b) target -= q[b];
      sub.wl[i] = support[b].first;
      sub.w[i] = 1.0f;
      prob[i] = q[b] / total;
    }
    WalkState ss;
    ss.layer = l;
    ss.depth = s.depth;
    ss.d = sample_uniform_sphere(rng_->next_double(), rng_->next_double());
    double acc[kWalkLanes] = {};
    if (volume_ != nullptr) {
      ss.pos = s.pos;
      volume_->sub_walk(ss, sub, acc, slot_);
    } else {
      WalkNee inner(st_, mt_, fac_, ls_, c_, shape_, mis_, n_, acc, *rng_);
      sub_walker_->walk(ss, sub, fac_, *rng_, inner);
    }
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0) continue;
      const int em = lanes.wl[k];
      double sum = 0;
      for (int i = 0; i < kWalkLanes; ++i) {
        if (sub.wl[i] >= em || acc[i] == 0) continue;
        double sigma = 0;
        for (size_t j = 0; j < L.fluors.size(); ++j) sigma += f[j] * L.fluors[j].emit[size_t(em) * n_ + sub.wl[i]];
        sum += sigma * acc[i] / prob[i];
      }
      if (sum > 0) add(k, lanes.w[k] * sum / (kWalkLanes * rate), true);
    }
  }

  static int max_lane_wl(const WalkLanes& lanes) {
    int m = 0;
    for (int k = 0; k < lanes.count; ++k)
      if (lanes.w[k] != 0) m = std::max(m, lanes.wl[k]);
    return m;
  }
  // Optical depth of the full layers above layer l (and of all layers) at bin wl.
  double above(int l, int wl) const {
    double tau = 0;
    for (int i = 0; i < l; ++i)
      if (!st_.layers[i].clear) tau += layer_mut(st_.layers[i], fac_.f[i], wl) * c_.len[i];
    return tau;
  }
  double through(int wl) const { return above(int(st_.layers.size()), wl); }
  void add(int k, double v, bool fluorescent) {
    if (acc_ != nullptr) {
      acc_[k] += v;
      return;
    }
    p_->L[k] += float(v);
    if (fluorescent) p_->Lf[k] += float(v);
  }

  const StackTables& st_;
  const MaterialTables& mt_;
  const StackPointFactors& fac_;
  const LightSample& ls_;
  const StackConnection& c_;
  const float* shape_;
  double mis_;
  int n_;
  PathLanes* p_ = nullptr;
  double* acc_ = nullptr;  // a sub-walk's sums per excitation lane
  const StackWalker* sub_walker_ = nullptr;
  ExcitationWalks* volume_ = nullptr;  // a volume walk's sub-walks (null: position-free ones)
  int slot_ = -1;
  Rng* rng_ = nullptr;
  std::vector<double> tex_;  // LED light reaching the current point, per emitting bin
};

struct NoNee {
  void moved(const glm::dvec3&, double) {}
  void collision(const WalkState&, const LaneCoefficients&, const WalkLanes&) {}
  void base_vertex(const WalkState&, const WalkLanes&) {}
};

// A next-event visitor or none (a material without a valid light connection).
struct NeeRef {
  WalkNee* nee = nullptr;
  void moved(const glm::dvec3&, double) {}
  void collision(const WalkState& s, const LaneCoefficients& c, const WalkLanes& l) {
    if (nee != nullptr) nee->collision(s, c, l);
  }
  void base_vertex(const WalkState& s, const WalkLanes& l) {
    if (nee != nullptr) nee->base_vertex(s, l);
  }
};

// The materials one volume walk can visit (a further one counts as the material the walk is in).
constexpr int kMaxVolumeMaterials = 8;
// The walk's lateral track is read every kLateralStep mm for a change of material (beyond the
// clearance LateralMaterials gives around the flight's start, where none can happen), and a change
// is located by bisection to kLateralPrecision mm; a flight parallel to the layers is read out to
// kLateralReach mm.
constexpr double kLateralStep = 0.01;
constexpr double kLateralPrecision = 1e-6;
constexpr double kLateralReach = 100.0;

// The layer of `st` that holds `depth`, for a walk travelling with vertical component dz: on a
// face, the layer the walk is moving into.
int layer_at_depth(const StackTables& st, double depth, double dz) {
  const int last = int(st.layers.size()) - 1;
  for (int j = 0; j < last; ++j)
    if (depth < st.layers[j].bottom || (depth == st.layers[j].bottom && dz > 0)) return j;
  return last;
}

// The volume walk (layered_bsdf.h): the camera walk and its scattered-excitation sub-walks, each
// run in the material under it and continued in the next where a flight crosses into it.
class VolumeWalk final : public ExcitationWalks {
 public:
  VolumeWalk(const VolumeWalkContext& ctx, const LightSample& ls, const float* shape, double mis, int n, PathLanes& p,
             Rng& rng)
      : ctx_(ctx), ls_(ls), shape_(shape), mis_(mis), n_(n), p_(p), rng_(rng) {}

  WalkResult camera_walk(WalkState& s, WalkLanes& lanes) {
    return drive(s, lanes, slot_of(ctx_.material), false, [&](int k) { return NeeRef{mats_[k].nee ? &*mats_[k].nee : nullptr}; });
  }

  void sub_walk(WalkState& s, WalkLanes& lanes, double* acc, int slot) override {
    std::array<std::optional<WalkNee>, kMaxVolumeMaterials> inner;
    drive(s, lanes, slot, true, [&](int k) {
      VolumeMaterial& vm = mats_[k];
      if (!vm.conn || !vm.conn->valid) return NeeRef{};
      if (!inner[k]) inner[k].emplace(vm.mt->stack, *vm.mt, vm.fac, ls_, *vm.conn, shape_, mis_, n_, acc, rng_);
      return NeeRef{&*inner[k]};
    });
  }

 private:
  // One material's part of the walk, made when the walk first reaches it.
  struct VolumeMaterial {
    int id = -1;
    const MaterialTables* mt = nullptr;
    StackPointFactors fac;
    std::optional<StackWalker> walker, sub_walker;
    std::optional<StackConnection> conn;
    std::optional<WalkNee> nee;  // the camera walk's next-event visitor (a valid connection only)
  };

  // Stops a flight where the material under it changes.
  struct RegionLimit {
    static constexpr bool kActive = true;
    VolumeWalk& walk;
    int slot;       // the material the flight is in
    int next = -1;  // after a stop: the slot of the material beyond it
    double limit(const WalkState& s, double t) {
      const glm::dvec2 dxy(s.d.x, s.d.y);
      const double speed = glm::length(dxy);  // lateral mm per mm of flight
      if (!(speed > 1e-12)) return std::numeric_limits<double>::infinity();
      const double tmax = std::min(t, kLateralReach / speed);
      // Within the clearance around the flight's start the material cannot change: no reads there.
      const double clear = walk.ctx_.under->clearance(s.pos) / speed;
      if (clear >= tmax) return std::numeric_limits<double>::infinity();
      const double from = clear;
      const int steps = std::max(1, int(std::ceil((tmax - from) * speed / kLateralStep)));
      double lo = from;
      for (int i = 1; i <= steps; ++i) {
        const double hi = from + (tmax - from) * i / steps;
        if (walk.slot_under(s.pos + hi * dxy, slot) == slot) {
          lo = hi;
          continue;
        }
        double a = lo, b = hi;
        while ((b - a) * speed > kLateralPrecision) {
          const double mid = 0.5 * (a + b);
          (walk.slot_under(s.pos + mid * dxy, slot) == slot ? a : b) = mid;
        }
        next = walk.slot_under(s.pos + b * dxy, slot);
        return b;
      }
      return std::numeric_limits<double>::infinity();
    }
  };

  // The slot of the material under `pos`; `current` where there is none to walk in.
  int slot_under(const glm::dvec2& pos, int current) {
    const int k = slot_of(ctx_.under->material_at(pos));
    return k < 0 ? current : k;
  }

  int slot_of(int id) {
    for (int k = 0; k < count_; ++k)
      if (mats_[k].id == id) return k;
    if (id < 0 || id >= int(ctx_.materials->size()) || count_ == kMaxVolumeMaterials) return -1;
    const MaterialTables& mt = (*ctx_.materials)[id];
    if (!mt.stack.enabled || mt.stack.layers.empty()) return -1;
    VolumeMaterial& vm = mats_[count_];
    vm.id = id;
    vm.mt = &mt;
    vm.fac = stack_point_factors(mt.stack, *ctx_.textures, ctx_.uv);
    vm.walker.emplace(mt.stack, mt, n_, WalkMode::kRadiance);
    vm.sub_walker.emplace(vm.walker->without_reradiation());
    if (ls_.valid) {
      vm.conn.emplace(mt.stack, ls_.wi, rng_);
      if (vm.conn->valid) {
        vm.nee.emplace(mt.stack, mt, vm.fac, ls_, *vm.conn, shape_, mis_, n_, p_, &*vm.sub_walker, &rng_);
        vm.nee->run_subwalks_in(this, count_);
      }
    }
    return count_++;
  }

  // Walks from s in the material of `slot`, on into the next wherever a flight crosses into it.
  template <class VisitorAt>
  WalkResult drive(WalkState& s, WalkLanes& lanes, int slot, bool sub, VisitorAt&& visitor_at) {
    for (;;) {
      VolumeMaterial& vm = mats_[slot];
      const StackWalker& w = sub ? *vm.sub_walker : *vm.walker;
      NeeRef v = visitor_at(slot);
      if (ctx_.under == nullptr) return w.walk(s, lanes, vm.fac, rng_, v);
      RegionLimit lim{*this, slot};
      WalkResult r = w.walk(s, lanes, vm.fac, rng_, v, lim);
      if (r.end != WalkEnd::kRegion) return r;
      slot = lim.next;
      s.layer = layer_at_depth(mats_[slot].mt->stack, s.depth, s.d.z);
    }
  }

  const VolumeWalkContext& ctx_;
  const LightSample& ls_;
  const float* shape_;
  double mis_;
  int n_;
  PathLanes& p_;
  Rng& rng_;
  std::array<VolumeMaterial, kMaxVolumeMaterials> mats_;
  int count_ = 0;
};

}  // namespace

StackPointFactors stack_point_factors(const StackTables& st, const std::vector<Texture>& textures, const glm::vec2& uv) {
  StackPointFactors fac;
  for (size_t l = 0; l < st.layers.size(); ++l)
    for (size_t j = 0; j < st.layers[l].fluors.size(); ++j) {
      const auto& f = st.layers[l].fluors[j];
      if (f.texture >= 0)
        fac.f[l][j] = std::max(0.0f, f.texture_offset + f.texture_scale * textures[f.texture].lookup(uv.x, uv.y));
    }
  return fac;
}

LayeredScatter layered_scatter(const MaterialTables& mt, const StackPointFactors& fac, const glm::dvec3& wo,
                               const LightSample& ls, const std::vector<std::vector<float>>& light_shapes, int n,
                               PathLanes& p, Rng& rng, const VolumeWalkContext* volume) {
  const StackTables& st = mt.stack;
  const double n0 = st.layers[0].ior;
  // The density MIS uses for "the stack's BSDF": the top lobe (rough tops) mixed with a cosine lobe.
  const double p_top = st.top.smooth() ? 0.0 : std::clamp(st.top_lobe.specular_albedo(wo.z), 0.05, 0.95);
  auto bsdf_pdf = [&](const glm::dvec3& wi) {
    double pd = cosine_hemisphere_pdf(wi.z);
    return p_top > 0 ? p_top * st.top_lobe.pdf(wo, wi) + (1.0 - p_top) * pd : pd;
  };

  double mis = 1.0;
  if (ls.valid) {
    if (ls.pdf_solid > 0) mis = power_heuristic(ls.pdf_solid, bsdf_pdf(ls.wi));
    if (!st.top.smooth()) {
      double fs = st.top.reflection(wo, ls.wi);
      const float* shape = light_shapes[ls.group].data();
      for (int k = 0; k < kLanes; ++k) p.add(k, p.beta[k] * fs * shape[p.wl[k]] * ls.g * mis);
    }
  }

  // Enter or reflect off the top (weight 1 either way: the interface is lossless).
  InterfaceEvent entry = st.top.scatter(-wo, rng);
  LayeredScatter c;
  if (entry.weight <= 0) return c;
  glm::dvec3 wi;
  if (!entry.transmitted) {
    wi = entry.dir;
    c.reflected = true;
    for (int k = 0; k < kLanes; ++k) p.rerad_prev[k] = false;
    c.pdf = st.top.smooth() ? 0.0 : bsdf_pdf(wi);
  } else {
    WalkLanes lanes;
    const double crossing = (st.ambient_ior / n0) * (st.ambient_ior / n0);
    for (int k = 0; k < kLanes; ++k) {
      lanes.wl[k] = p.wl[k];
      lanes.w[k] = float(p.beta[k] * crossing);
      lanes.fl[k] = p.fl[k];
      lanes.rerad[k] = false;
    }
    StackWalker walker(st, mt, n, WalkMode::kRadiance);
    WalkState s;
    s.d = entry.dir;
    WalkResult res;
    if (volume != nullptr) {
      VolumeWalk vw(*volume, ls, ls.valid ? light_shapes[ls.group].data() : nullptr, mis, n, p, rng);
      res = vw.camera_walk(s, lanes);
    } else if (ls.valid) {
      StackConnection conn(st, ls.wi, rng);
      if (conn.valid) {
        StackWalker sub_walker = walker.without_reradiation();
        WalkNee nee(st, mt, fac, ls, conn, light_shapes[ls.group].data(), mis, n, p, &sub_walker, &rng);
        res = walker.walk(s, lanes, fac, rng, nee);
      } else {
        NoNee none;
        res = walker.walk(s, lanes, fac, rng, none);
      }
    } else {
      NoNee none;
      res = walker.walk(s, lanes, fac, rng, none);
    }
    c.walk = res;
    if (res.end != WalkEnd::kExitTop) return c;
    wi = res.dir;
    for (int k = 0; k < kLanes; ++k) {
      p.beta[k] = lanes.w[k];
      p.wl[k] = lanes.wl[k];
      p.fl[k] = lanes.fl[k];
      p.rerad_prev[k] = lanes.rerad[k] && res.direct;
    }
    c.pdf = res.direct ? bsdf_pdf(wi) : 0.0;
  }
  if (wi.z <= 0) return c;
  c.ok = true;
  c.wi = wi;
  return c;
}

namespace {

// Where the table-mode continuation comes from: the top's specular lobe with probability p_top
// (rough tops), the Fresnel mirror with probability F (smooth tops), a cosine lobe otherwise.
struct TableLobes {
  const StackTables& st;
  glm::dvec3 wo;
  double p_top = 0;     // rough: probability of sampling the top lobe
  double f_mirror = 0;  // smooth: Fresnel reflectance toward the mirror direction
  TableLobes(const StackTables& s, const glm::dvec3& w) : st(s), wo(w) {
    if (st.top.smooth()) f_mirror = fresnel_dielectric(wo.z, st.layers[0].ior / st.ambient_ior);
    else p_top = std::clamp(st.top_lobe.specular_albedo(wo.z), 0.05, 0.95);
  }
  // Solid-angle density of a non-mirror direction.
  double pdf(const glm::dvec3& wi) const {
    double pd = cosine_hemisphere_pdf(wi.z);
    if (st.top.smooth()) return (1.0 - f_mirror) * pd;
    return p_top * st.top_lobe.pdf(wo, wi) + (1.0 - p_top) * pd;
  }
};

void table_light_sample(const MaterialTables& mt, const TableLobes& lobes, const LightSample& ls,
                        const std::vector<std::vector<float>>& light_shapes, PathLanes& p) {
  const StackTables& st = mt.stack;
  const StackResponse& r = *st.response;
  const glm::dvec3& wo = lobes.wo;
  const double mis = ls.pdf_solid > 0 ? power_heuristic(ls.pdf_solid, lobes.pdf(ls.wi)) : 1.0;
  const double fs = st.top.smooth() ? 0.0 : st.top.reflection(wo, ls.wi);
  const StackResponse::Weights a = r.weights(wo.z), b = r.weights(ls.wi.z);
  const float* shape = light_shapes[ls.group].data();
  for (int k = 0; k < kLanes; ++k) {
    if (p.beta[k] == 0) continue;
    const int em = p.wl[k];
    double reflected = p.beta[k] * (fs + r.elastic_at(a, b, em)) * shape[em] * ls.g * mis;
    double fluo = r.direct.empty() ? 0.0 : p.beta[k] * r.direct_at(ls.group, a, b, em) * ls.g;
    p.L[k] += float(reflected + fluo);
    p.Lf[k] += float((p.fl[k] ? reflected : 0.0) + fluo);
  }
}

}  // namespace

LayeredScatter layered_table_scatter(const MaterialTables& mt, const glm::dvec3& wo, const LightSample& ls,
                                     const std::vector<std::vector<float>>& light_shapes, PathLanes& p, Rng& rng) {
  const StackTables& st = mt.stack;
  const StackResponse& r = *st.response;
  const TableLobes lobes(st, wo);
  if (ls.valid) table_light_sample(mt, lobes, ls, light_shapes, p);

  LayeredScatter c;
  // The mirror of a smooth top: weight 1 (probability F, value F).
  if (st.top.smooth() && rng.next_double() < lobes.f_mirror) {
    c.ok = true;
    c.reflected = true;
    c.wi = glm::dvec3(-wo.x, -wo.y, wo.z);
    c.pdf = 0;
    for (int k = 0; k < kLanes; ++k) p.rerad_prev[k] = false;
    return c;
  }
  glm::dvec3 wi;
  if (!st.top.smooth() && rng.next_double() < lobes.p_top) {
    wi = st.top_lobe.sample(wo, rng.next_double(), rng.next_double());
    c.reflected = true;
  } else {
    wi = sample_cosine_hemisphere(rng.next_double(), rng.next_double());
  }
  if (wi.z <= 0) return c;
  const double pdf = lobes.pdf(wi);
  if (!(pdf > 0)) return c;
  const double fs = st.top.smooth() ? 0.0 : st.top.reflection(wo, wi);
  const StackResponse::Weights a = r.weights(wo.z), b = r.weights(wi.z);
  const double geo = wi.z / pdf;
  for (int k = 0; k < kLanes; ++k) {
    if (p.beta[k] == 0) continue;
    const int em = p.wl[k];
    const double el = r.elastic_at(a, b, em);
    const double fl = r.fluor.empty() ? 0.0 : r.fluor_sum_at(a, b, em);
    const double tot = fs + el + fl;
    if (!(tot > 0)) {
      p.beta[k] = 0;
      continue;
    }
    p.rerad_prev[k] = false;
    if (rng.next_double() * tot >= fs + el) {
      p.wl[k] = r.sample_excitation(a, b, em, rng.next_double(), rng.next_float());
      p.fl[k] = true;
      p.rerad_prev[k] = true;  // next-event estimation summed the LED's direct excitation
    }
    p.beta[k] = float(p.beta[k] * tot * geo);
  }
  c.ok = true;
  c.wi = wi;
  c.pdf = pdf;
  return c;
}

}  // namespace ofl
