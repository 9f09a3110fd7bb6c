// Layered tissue at a path vertex (see layered_bsdf.h).
#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/render/layered_bsdf.h"

#include "renderer/render/stack_walk.h"

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

// Next-event estimation at every vertex of the walk, gathered into the camera path's lanes.
class WalkNee {
 public:
  WalkNee(const StackTables& st, const MaterialTables& mt, const StackPointFactors& fac, const LightSample& ls,
          const StackConnection& conn, const float* shape, double mis, int n, PathLanes& p)
      : st_(st), mt_(mt), fac_(fac), ls_(ls), c_(conn), shape_(shape), mis_(mis), n_(n), p_(p),
        tex_(st.led_support[ls.group].size()) {}

  void moved(const glm::dvec3&, double) {}

  void collision(const WalkState& s, const LaneCoefficients& c, const WalkLanes& lanes) {
    const int l = s.layer;
    if (l > c_.reach) return;
    const StackLayerTables& L = st_.layers[l];
    const double dz = s.depth - L.top;
    const double common = c_.fresnel_t[l] * c_.top_weight / c_.mu[l] * ls_.g;
    const double hg = hg_phase(L.g, glm::dot(c_.dir[l], -s.d));
    int max_wl = 0;
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0) continue;
      max_wl = std::max(max_wl, lanes.wl[k]);
      double tau = above(l, lanes.wl[k]) + double(c.mut[k]) * dz / c_.mu[l];
      double v = lanes.w[k] * c.mus[k] * hg * std::exp(-tau) * shape_[lanes.wl[k]] * common * mis_;
      add(k, v, lanes.fl[k]);
    }
    if (L.fluors.empty() || L.fluors.front().emit.empty()) return;
    // Direct excitation: LED light reaching this point unscattered, absorbed and re-emitted at each
    // lane's wavelength; summed over the LED's bins.
    const auto& support = st_.led_support[ls_.group];
    double* tex = tex_.data();
    int m = 0;
    for (const auto& [ex, S] : support) {
      if (ex >= max_wl) break;
      double tau = above(l, ex) + double(layer_mut(L, fac_.f[l], ex)) * dz / c_.mu[l];
      tex[m++] = std::exp(-tau) * S;
    }
    if (m == 0) return;
    const double iso = common / (4.0 * kPi);
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

  void base_vertex(const WalkState& s, const WalkLanes& lanes) {
    const int l = int(st_.layers.size()) - 1;
    if (l > c_.reach) return;
    const double common = c_.fresnel_t[l] * c_.top_weight * ls_.g / kPi;
    int max_wl = 0;
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0) continue;
      max_wl = std::max(max_wl, lanes.wl[k]);
      const int em = lanes.wl[k];
      add(k, lanes.w[k] * mt_.reflectance[em] * std::exp(-through(em)) * shape_[em] * mis_ * common, lanes.fl[k]);
    }
    if (mt_.fluorophores.empty()) return;
    // The base's fluorophores excited by LED light that crossed every layer (summed over its bins).
    const auto& support = st_.led_support[ls_.group];
    double* tex = tex_.data();
    int m = 0;
    for (const auto& [ex, S] : support) {
      if (ex >= max_wl) break;
      tex[m++] = std::exp(-through(ex)) * S;
    }
    for (int k = 0; k < lanes.count; ++k) {
      if (lanes.w[k] == 0) continue;
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
  // Optical depth of the full layers above layer l (and of all layers) at bin wl.
  double above(int l, int wl) const {
    double tau = 0;
    for (int i = 0; i < l; ++i)
      if (!st_.layers[i].clear) tau += layer_mut(st_.layers[i], fac_.f[i], wl) * c_.len[i];
    return tau;
  }
  double through(int wl) const { return above(int(st_.layers.size()), wl); }
  void add(int k, double v, bool fluorescent) {
    p_.L[k] += float(v);
    if (fluorescent) p_.Lf[k] += float(v);
  }

  const StackTables& st_;
  const MaterialTables& mt_;
  const StackPointFactors& fac_;
  const LightSample& ls_;
  const StackConnection& c_;
  const float* shape_;
  double mis_;
  int n_;
  PathLanes& p_;
  std::vector<double> tex_;  // LED light reaching the current point, per emitting bin
};

struct NoNee {
  void moved(const glm::dvec3&, double) {}
  void collision(const WalkState&, const LaneCoefficients&, const WalkLanes&) {}
  void base_vertex(const WalkState&, const WalkLanes&) {}
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
                               PathLanes& p, Rng& rng) {
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
    if (ls.valid) {
      StackConnection conn(st, ls.wi, rng);
      if (conn.valid) {
        WalkNee nee(st, mt, fac, ls, conn, light_shapes[ls.group].data(), mis, n, p);
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

}  // namespace ofl
