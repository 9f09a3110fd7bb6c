// The spatial transport's vertex (see spatial_vertex.h).
#include "renderer/render/integrator/spatial_vertex.h"

#include "renderer/render/integrator/led_connection.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "renderer/render/spatial/spatial_tables.h"
#include "renderer/render/spatial/surface_probe.h"
#include "renderer/render/stack/stack_response.h"

namespace ofl {

namespace {

constexpr double kMmPerMetre = 1000.0;
constexpr int kMaxSlices = 64;

int pick_index(const double* w, int n, double u) {
  double total = 0;
  for (int i = 0; i < n; ++i) total += w[i];
  double t = u * total;
  for (int i = 0; i < n; ++i) {
    if (t < w[i]) return i;
    t -= w[i];
  }
  for (int i = n - 1; i >= 0; --i)
    if (w[i] > 0) return i;
  return 0;
}

int pick_axis(double u) {
  return u < kProbeAxisProbability[0] ? 0 : u < kProbeAxisProbability[0] + kProbeAxisProbability[1] ? 1 : 2;
}

int pick_cosine(const StackProfiles::CosineWeights& cw, double u) { return u < cw.w[0] ? cw.c[0] : cw.c[1]; }

// A point found by a probe, on the viewer's side: its authored normal must face the same way as
// x_o's (on a closed, consistently wound mesh the far side of a thin part faces the other way: light
// does not cross to it), and its normals are then turned as x_o's were. False: not on this side.
bool same_side(SurfacePoint& s, const SurfacePoint& xo) {
  const glm::dvec3 n_o = xo.flipped ? -xo.ng : xo.ng;
  if (glm::dot(s.ng, n_o) <= 0) return false;
  if (xo.flipped) {
    s.ng = -s.ng;
    s.ns = -s.ns;
    s.flipped = true;
  }
  return true;
}

}  // namespace

struct SpatialTransport::Vertex {
  const SurfacePoint& xo;
  unsigned geom;
  const Frame& frame;
  glm::dvec3 wo;
  const MaterialTables& mt;
  PathLanes& p;
  const SpatialStack& S;
  const StackResponse& R;
  double mu_o = 1;
  bool smooth = true;
  double p_spec = 0;  // probability that the continuation is the top interface's reflection at x_o
  int light = -1, group = 0;
  double mu_i_proxy = 1;  // the light's cosine at x_o, standing in for its cosine at the entry point
  SpatialStack::Cosines co, ci_proxy;  // the profiles' interpolation weights at mu_o and mu_i_proxy
  // The anchor (docs/layered-tissue.md, "Lateral transport", estimator): the LED connection at x_o,
  // to the same point on the LED as every entry point's (the same seed), and its MIS weight.
  uint64_t led_seed = 0;
  LightSample at_o;
  double w_o = 1;
};

// The materials along a segment between two surface points and the share of the segment in each
// (docs/layered-tissue.md, "Regions and lateral transport").
struct SpatialTransport::Chord {
  static constexpr int kMax = 4;
  int n = 0;
  int material[kMax] = {};
  double share[kMax] = {};
};

struct SpatialTransport::Entry {
  bool found = false;
  bool fluorescent = false;
  double q_nee = 1;             // probability that this strategy was run (its next-event estimates are divided by it)
  double q_cont = 1;            // probability that the path continues from this entry (within the subsurface)
  SurfacePoint xi;              // entry point, normals toward the viewer's side
  int material = -1;            // governing material (elastic) or the emission point's (fluorescent)
  double pdf = 0;               // elastic: area density of x_i (1/mm^2)
  double r_mm = 0;              // elastic: |x_i - x_o|
  int z = 0;                    // fluorescent: depth slice
  double rho_m = 0, rho_i = 0;  // fluorescent: x_o to x_m (planar), x_m to x_i (mm)
  double pdf_m = 0, pdf_i = 0;  // fluorescent: densities of (Z, x_m) and of x_i given x_m
  // The materials along the segment x_o -> x_i (elastic) or x_o -> x_m (fluorescent: the emission
  // leg), and along x_m -> x_i (fluorescent: the excitation leg).
  Chord chord, ex_chord;
};

// The segment between x_o and x_i is read at this many points (the midpoints of equal parts).
constexpr int kChordPoints = 16;

// The share of entry points (elastic) and emission points (fluorescent) drawn uniformly over the
// disc of the scene's widest search radius instead of from x_o's own profile. Across a region
// boundary the light is weighed by the other material's profile, which may reach further than x_o's
// or hold mass in rings where x_o's sampled profile holds none; without this share such light
// would never be sampled, and the estimate would not be unbiased across regions. Within one
// material it costs a tenth of the samples.
constexpr double kDefensive = 0.1;

namespace {

bool same_layer(const TissueLayer& a, const TissueLayer& b) {
  if (a.ior != b.ior || a.g != b.g || a.mua != b.mua || a.mus != b.mus || a.fluorophores.size() != b.fluorophores.size())
    return false;
  for (size_t i = 0; i < a.fluorophores.size(); ++i)
    if (a.fluorophores[i].eem != b.fluorophores[i].eem || a.fluorophores[i].mua_peak_per_mm != b.fluorophores[i].mua_peak_per_mm)
      return false;
  return true;
}

// The layer at depth z (mm) below the top, or nullptr below the last finite one.
const TissueLayer* layer_at(const LayerStack& s, double z) {
  double top = 0;
  for (const TissueLayer& l : s.layers) {
    if (l.semi_infinite() || z < top + l.thickness_mm) return &l;
    top += l.thickness_mm;
  }
  return nullptr;
}

}  // namespace

double differing_depth_mm(const LayerStack& a, const LayerStack& b) {
  constexpr int kSteps = 100;
  double d = 0;
  for (int i = 0; i < kSteps; ++i) {
    const double z = (i + 0.5) * kPassageMm / kSteps;
    const TissueLayer *la = layer_at(a, z), *lb = layer_at(b, z);
    if (!(la && lb ? same_layer(*la, *lb) : la == lb)) d += kPassageMm / kSteps;
  }
  return d;
}

SpatialTransport::SpatialTransport(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables)
    : scene_(scene), embree_(embree), t_(tables) {
  for (const MaterialTables& m : tables.materials)
    if (m.stack.enabled && m.stack.spatial) wide_mm_ = std::max(wide_mm_, m.stack.spatial->search_mm);
  const size_t n = scene.materials.size();
  passage_mm_.assign(n * n, 0.0);
  for (size_t a = 0; a < n; ++a)
    for (size_t b = 0; b < n; ++b)
      if (a != b && spatial_material(int(a)) && spatial_material(int(b)))
        passage_mm_[a * n + b] = differing_depth_mm(scene.materials[a].stack, scene.materials[b].stack);
}

bool SpatialTransport::spatial_material(int m) const {
  return m >= 0 && t_.materials[m].stack.enabled && t_.materials[m].stack.spatial && t_.materials[m].stack.response;
}

LightSample SpatialTransport::connect(const Vertex& v, const SurfacePoint& x, const Frame& f, RayCounts& counts,
                                      RayLog* log) const {
  // The subsurface light is chosen by power (scatter below), so its probability is the power one.
  // The point on the LED comes from the vertex's own seed: the same at x_o and at every entry point,
  // so that the anchor and the entries' estimates move together (their difference is what is noisy).
  Rng led(v.led_seed, 0x4C4544ULL);
  return connect_to_led(scene_, embree_, t_, v.light, t_.light_select.pdf(v.light), x, f, led, counts, log);
}

// The LED connection at x_o, shared by the top lobe and the anchor, and the anchor's reflected and
// fluorescent light: the position-free table's next-event estimate at x_o. Each entry point's
// estimate then adds the difference between the spatial transport and this (entry_light).
void SpatialTransport::anchor(Vertex& v, const Plan& pl, RayCounts& counts, RayLog* log) const {
  if (v.light < 0) return;
  v.at_o = connect(v, v.xo, v.frame, counts, log);
  const LightSample& ls = v.at_o;
  if (!ls.valid) return;
  // The weight the reflected anchor gets against the continuation's hits (any constant keeps the
  // estimate unbiased; this one follows the entries' own weight).
  const double cont = (1.0 - v.p_spec) * cosine_hemisphere_pdf(ls.wi.z) * (1.0 - pl.cont_fl);
  v.w_o = ls.pdf_solid > 0 ? power_heuristic(ls.pdf_solid, cont) : 1.0;
  const auto a = v.R.weights(v.mu_o), b = v.R.weights(ls.wi.z);
  const float* shape = t_.light_shape[ls.group].data();
  const bool fluorescent = v.S.fluorescent && !v.R.direct.empty();
  for (int k = 0; k < kLanes; ++k) {
    if (v.p.beta[k] == 0) continue;
    const int wl = v.p.wl[k];
    v.p.add(k, v.p.beta[k] * v.R.elastic_at(a, b, wl) * shape[wl] * ls.g * v.w_o);
    if (!fluorescent) continue;
    const double fl = v.p.beta[k] * v.R.direct_at(ls.group, a, b, wl) * ls.g;
    v.p.L[k] += float(fl);
    v.p.Lf[k] += float(fl);
  }
}

// Next-event estimation of the top interface's specular lobe at x_o (rough tops; a smooth top's
// mirror is found by the continuation), through the anchor's connection.
void SpatialTransport::top_light(Vertex& v) const {
  const LightSample& ls = v.at_o;
  if (v.smooth || !ls.valid) return;
  const GgxCoating& lobe = v.mt.stack.top_lobe;
  const double mis = ls.pdf_solid > 0 ? power_heuristic(ls.pdf_solid, v.p_spec * lobe.pdf(v.wo, ls.wi)) : 1.0;
  const double fs = v.mt.stack.top.reflection(v.wo, ls.wi);
  const float* shape = t_.light_shape[ls.group].data();
  for (int k = 0; k < kLanes; ++k) v.p.add(k, v.p.beta[k] * fs * shape[v.p.wl[k]] * ls.g * mis);
}

// How the two subsurface strategies are run (spatial_vertex.h): what each is expected to add by
// next-event estimation (position-free, at the light's cosine at x_o) and to carry on into the
// continuation (the table's albedos at the viewer's cosine), over the lanes.
SpatialTransport::Plan SpatialTransport::plan(const Vertex& v) const {
  Plan pl;
  const bool fluorescent = v.S.fluorescent && !v.R.fluor.empty();
  const auto a = v.R.weights(v.mu_o), b = v.R.weights(v.mu_i_proxy);
  const float* shape = v.light >= 0 ? t_.light_shape[v.group].data() : nullptr;
  double nee_el = 0, nee_fl = 0, cont_el = 0, cont_fl = 0;
  for (int k = 0; k < kLanes; ++k) {
    const double beta = v.p.beta[k];
    if (beta == 0) continue;
    const int wl = v.p.wl[k];
    if (shape) nee_el += beta * v.R.elastic_at(a, b, wl) * shape[wl];
    if (shape && fluorescent && !v.R.direct.empty()) nee_fl += beta * v.R.direct_at(v.group, a, b, wl);
    cont_el += beta * v.R.elastic_at(a, a, wl);
    if (fluorescent) cont_fl += beta * v.R.fluor_sum_at(a, a, wl);
  }
  // The continuation: top reflection with p_spec, else one entry, in proportion to what it carries
  // (kept within [0.1, 0.9] when both carry something).
  const double c_fl = cont_el + cont_fl > 0 ? cont_fl / (cont_el + cont_fl) : 0.0;
  pl.cont_fl = cont_fl > 0 && cont_el > 0 ? std::clamp(c_fl, 0.1, 0.9) : (cont_fl > 0 ? 1.0 : 0.0);
  // Next-event estimation: the strategy expected to add more always runs, the other in proportion
  // (at least a tenth of the time), and each runs anyway when the path continues from its entry.
  const double top = std::max(nee_el, nee_fl);
  pl.run_el = top > 0 ? std::clamp(nee_el / top, nee_el > 0 ? 0.1 : 0.0, 1.0) : 0.0;
  pl.run_fl = top > 0 ? std::clamp(nee_fl / top, nee_fl > 0 ? 0.1 : 0.0, 1.0) : 0.0;
  return pl;
}

SpatialTransport::Entry SpatialTransport::sample_elastic(Vertex& v, Rng& rng, RayCounts& counts) const {
  Entry e;
  // The lanes' mixture: half in proportion to the throughput, half to the reflected light each lane is
  // expected to get from the chosen LED (so that the LED's own band, which carries most reflected
  // light, samples its own short profile), at the light's cosine at x_o.
  double alpha[kLanes], lit[kLanes], bsum = 0, lsum = 0;
  const auto a = v.R.weights(v.mu_o), b = v.R.weights(v.mu_i_proxy);
  const float* shape = v.light >= 0 ? t_.light_shape[v.group].data() : nullptr;
  for (int k = 0; k < kLanes; ++k) {
    lit[k] = shape && v.p.beta[k] > 0 ? v.p.beta[k] * v.R.elastic_at(a, b, v.p.wl[k]) * shape[v.p.wl[k]] : 0.0;
    bsum += v.p.beta[k];
    lsum += lit[k];
  }
  if (!(bsum > 0)) return e;
  double asum = 0;
  for (int k = 0; k < kLanes; ++k) asum += alpha[k] = 0.2 * v.p.beta[k] / bsum + 0.8 * (lsum > 0 ? lit[k] / lsum : v.p.beta[k] / bsum);
  const int k = pick_index(alpha, kLanes, rng.next_double());
  const int c = pick_cosine(v.co, rng.next_double());
  const bool wide = rng.next_double() < kDefensive;
  const double u1 = rng.next_double(), u2 = rng.next_double();
  const double r = wide ? wide_mm_ * std::sqrt(u1) : radial::sample(v.S.el_rings(), &v.S.el_cdf[v.S.el_at(c, v.p.wl[k])], u1, u2);
  const double phi = 2.0 * kPi * rng.next_double();
  const int axis = pick_axis(rng.next_double());
  ++counts.probe;
  const double search = wide ? wide_mm_ : v.S.search_mm;
  const ProbeResult pr = probe_around(embree_, v.geom, v.xo.p, v.frame, r, phi, axis, search, rng.next_double());
  if (!pr.found) return e;
  e.xi = pr.sp;
  if (!same_side(e.xi, v.xo)) return e;
  const double uniform = 1.0 / (kPi * wide_mm_ * wide_mm_);
  e.pdf = probe_density(v.xo.p, v.frame, e.xi, pr.hits, [&](double rr) {
    double d = rr < wide_mm_ ? kDefensive * uniform : 0.0;
    const int ring = rr < v.S.search_mm ? v.S.el_rings().ring_of(rr) : -1;
    if (ring < 0) return d;
    double p = 0;
    for (int j = 0; j < kLanes; ++j)
      if (alpha[j] > 0) p += alpha[j] * v.S.elastic_density_in(v.co, v.p.wl[j], ring);
    return d + (1.0 - kDefensive) * p / asum;
  });
  e.r_mm = glm::length(e.xi.p - v.xo.p) * kMmPerMetre;
  const int mi = e.xi.material;
  if (!spatial_material(mi) || !(e.pdf > 0)) return e;
  e.material = mi;
  e.found = true;
  chord_materials(v, v.xo, e.xi, e.chord);
  return e;
}

// The materials along the segment from a to b and the share of the segment in each
// (docs/layered-tissue.md, "Regions and lateral transport"): the segment's points, with position
// and texture coordinates interpolated between its ends, resolved as the surface resolves its
// `regions`. Without regions the segment is a's material.
void SpatialTransport::chord_materials(const Vertex& v, const SurfacePoint& a, const SurfacePoint& b, Chord& c) const {
  const int base = embree_.info(v.geom).material;
  c.n = 1;
  c.material[0] = a.material;
  c.share[0] = 1.0;
  if (base < 0 || !scene_.materials[base].dispatches()) return;
  c.share[0] = 0.0;
  for (int s = 0; s < kChordPoints; ++s) {
    const double t = (s + 0.5) / kChordPoints;
    const glm::dvec3 p = a.p + t * (b.p - a.p);
    const glm::vec2 uv = a.uv + float(t) * (b.uv - a.uv);
    int m = resolve_material(scene_, base, uv.x, uv.y, p);
    if (!spatial_material(m)) m = a.material;
    int j = 0;
    while (j < c.n && c.material[j] != m) ++j;
    if (j == c.n) {
      if (j == Chord::kMax) j = 0;  // a fifth material: counted as a's
      else c.material[c.n++] = m;
    }
    c.share[j] += 1.0 / kChordPoints;
  }
}

SpatialTransport::Entry SpatialTransport::sample_fluorescent(Vertex& v, Rng& rng, RayCounts& counts) const {
  Entry e;
  e.fluorescent = true;
  const SpatialStack& S = v.S;
  const int Z = std::min(S.Z, kMaxSlices);
  // Per lane, the depth weights of its direct fluorescence (at the light's cosine at x_o) and the
  // lane's share of the proposal.
  double omega[kLanes][kMaxSlices], alpha[kLanes], asum = 0;
  for (int k = 0; k < kLanes; ++k) {
    alpha[k] = 0;
    if (v.p.beta[k] == 0) continue;
    S.slice_weights(v.group, v.co, v.ci_proxy, v.p.wl[k], omega[k]);
    double total = 0;
    for (int z = 0; z < Z; ++z) total += omega[k][z];
    if (!(total > 0)) continue;
    for (int z = 0; z < Z; ++z) omega[k][z] /= total;
    alpha[k] = v.p.beta[k] * total;
    asum += alpha[k];
  }
  if (!(asum > 0)) return e;
  const int k = pick_index(alpha, kLanes, rng.next_double());
  const int z = pick_index(omega[k], Z, rng.next_double());
  const int c = pick_cosine(v.co, rng.next_double());
  const bool wide = rng.next_double() < kDefensive;
  const double u1 = rng.next_double(), u2 = rng.next_double();
  const double rho = wide ? wide_mm_ * std::sqrt(u1) : radial::sample(S.leg_rings(), &S.leg_cdf[S.leg_at(c, v.p.wl[k], z)], u1, u2);
  const double phi = 2.0 * kPi * rng.next_double();
  e.z = z;
  e.rho_m = rho;
  // The density of x_m in x_o's tangent plane: the lanes' mixture of x_o's emission legs at slice z
  // (the slice drawn in proportion to omega), plus the uniform share over the wide disc, which any
  // slice may take (the slice's own probability, sum over lanes of alpha omega, times it).
  double p_legs = 0, p_slice = 0;
  const int ring = rho < S.search_mm ? S.leg_rings().ring_of(rho) : -1;
  for (int j = 0; j < kLanes; ++j) {
    if (!(alpha[j] > 0)) continue;
    p_slice += alpha[j] / asum * omega[j][z];
    if (ring >= 0) p_legs += alpha[j] / asum * omega[j][z] * S.emission_density_in(v.co, v.p.wl[j], z, ring);
  }
  e.pdf_m = (1.0 - kDefensive) * p_legs + (rho < wide_mm_ ? kDefensive * p_slice / (kPi * wide_mm_ * wide_mm_) : 0.0);
  // The surface above the emission point: the mesh's crossing nearest to x_o's tangent plane.
  const glm::dvec3 mid = v.xo.p + (rho / kMmPerMetre) * (std::cos(phi) * v.frame.x + std::sin(phi) * v.frame.y);
  const double h = S.search_mm / kMmPerMetre;
  SurfacePoint hits[kMaxProbeHits];
  ++counts.probe;
  const int nh = probe_segment(embree_, v.geom, mid + h * v.frame.z, mid - h * v.frame.z, hits);
  if (nh == 0) return e;
  int best = -1;
  for (int i = 0; i < nh; ++i)
    if (same_side(hits[i], v.xo) && (best < 0 || glm::length(hits[i].p - mid) < glm::length(hits[best].p - mid))) best = i;
  if (best < 0) return e;
  const SurfacePoint& xm = hits[best];
  if (!spatial_material(xm.material)) return e;
  e.material = xm.material;
  // The entry point: the excitation leg of the emission point's material from x_m.
  const SpatialStack& Sm = *t_.materials[xm.material].stack.spatial;
  const Frame fm(xm.ng);
  const int ci = pick_cosine(v.ci_proxy, rng.next_double());
  const double r = radial::sample(Sm.leg_rings(), &Sm.ex_cdf[Sm.ex_at(v.group, ci, z)], rng.next_double(), rng.next_double());
  const double phi_i = 2.0 * kPi * rng.next_double();
  const int axis = pick_axis(rng.next_double());
  ++counts.probe;
  const ProbeResult pr = probe_around(embree_, v.geom, xm.p, fm, r, phi_i, axis, Sm.search_mm, rng.next_double());
  if (!pr.found) return e;
  e.xi = pr.sp;
  if (!same_side(e.xi, v.xo)) return e;
  e.pdf_i = probe_density(xm.p, fm, e.xi, pr.hits, [&](double rr) { return Sm.excitation_density(v.group, v.ci_proxy, z, rr); });
  e.rho_i = glm::length(e.xi.p - xm.p) * kMmPerMetre;
  e.found = spatial_material(e.xi.material) && e.pdf_m > 0 && e.pdf_i > 0;
  if (e.found) {
    chord_materials(v, v.xo, xm, e.chord);
    chord_materials(v, xm, e.xi, e.ex_chord);
  }
  return e;
}

// The elastic BSSRDF's value per lane (1/(sr mm^2)) for light entering at e.xi with cosine mu_i and
// leaving x_o toward the viewer: the table's directional factor times the exit profile at |x_i - x_o|.
// Within one material that is the material's own; where the segment from x_o to x_i crosses
// regions, the product of each crossed material's value raised to its share of the path
// (docs/layered-tissue.md, "Regions and lateral transport"): light is attenuated by each material in
// proportion to the way it travels in it, as diffusion attenuates it, with the darker materials'
// shares raised per lane (darker_shares, by the directional factor); the rule is reciprocal.
void SpatialTransport::elastic_values(const Vertex& v, const Entry& e, double mu_i, double* f) const {
  auto one = [&](const MaterialTables& m, double* dir, double* out) {
    const StackResponse& R = *m.stack.response;
    const SpatialStack& S = *m.stack.spatial;
    const auto a = R.weights(v.mu_o), b = R.weights(mu_i);
    for (int k = 0; k < kLanes; ++k) {
      dir[k] = v.p.beta[k] == 0 ? 0.0 : R.elastic_at(a, b, v.p.wl[k]);
      out[k] = v.p.beta[k] == 0 ? 0.0 : dir[k] * S.elastic_density(v.co, v.p.wl[k], e.r_mm);
    }
  };
  const Chord c = crossing_shares(e.chord, v.xo.material, e.xi.material, e.r_mm);
  double dir[Chord::kMax][kLanes], g[Chord::kMax][kLanes];
  if (c.n == 1) return one(t_.materials[c.material[0]], dir[0], f);
  for (int j = 0; j < c.n; ++j)
    if (c.share[j] > 0) one(t_.materials[c.material[j]], dir[j], g[j]);
  for (int k = 0; k < kLanes; ++k) {
    f[k] = 0.0;
    if (v.p.beta[k] == 0) continue;
    double refl[Chord::kMax], share[Chord::kMax];
    for (int j = 0; j < c.n; ++j) refl[j] = c.share[j] > 0 ? dir[j][k] : 0.0;
    darker_shares(c.n, c.share, refl, kDarkerShareGamma, share);
    f[k] = 1.0;
    for (int j = 0; j < c.n; ++j)
      if (share[j] > 0) f[k] *= std::pow(g[j][k], share[j]);
  }
}

// The shares of a path from x_i (material mi) to x_o (material mo) along a chord of length r_mm
// (docs/layered-tissue.md, "Regions and lateral transport"): the path goes down through the layers
// that tell the materials apart under x_i, along the chord, and up through them under x_o, so each
// end's material counts the depth L over which the chord's materials differ (at most kPassageMm)
// once, on top of its share of the chord. Between the passages the light runs deeper the further
// apart the ends are (about r / 2 at the middle), below the layers that differ, so the chord counts
// with the length c = r / (1 + r / (2 L)) it spends among them (r when short, 2 L at most):
// share_m = (L [m = mi] + L [m = mo] + c share_m) / (2 L + c).
// Symmetric in the two ends (reciprocal); with nothing to cross, the chord itself.
SpatialTransport::Chord SpatialTransport::crossing_shares(const Chord& chord, int mo, int mi, double r_mm) const {
  const double L = std::max(passage_among(chord, mo, mi), passage_among(chord, mi, mo));
  if (!(L > 0)) return chord;
  const int ends[2] = {mo, mi};
  return with_passages(chord, ends, 2, L, chord_among_passages_mm(std::max(r_mm, 0.0), L));
}

// The shares of a fluorescence leg of rho_mm between its surface end (material `surface`: x_o for
// the emission leg, x_i for the excitation leg) and the emission point at depth z_mm
// (docs/layered-tissue.md, "Regions and lateral transport"): the leg passes through the layers that
// tell the materials apart (L deep) under its surface end only, over min(z, L); of its chord the
// part among those layers is rho L / (L + z): the whole chord for an emission at the surface, less
// the deeper the emission.
SpatialTransport::Chord SpatialTransport::leg_shares(const Chord& chord, int surface, int emitter, double rho_mm,
                                                     double z_mm) const {
  const double L = passage_among(chord, surface, emitter);
  if (!(L > 0)) return chord;
  const double z = std::max(z_mm, 0.0);
  return with_passages(chord, &surface, 1, std::min(z, L), std::max(rho_mm, 0.0) * L / (L + z));
}

// The deepest passage (mm) between material `end` and the other end's or any material of the chord.
double SpatialTransport::passage_among(const Chord& chord, int end, int other) const {
  const size_t n = scene_.materials.size();
  auto pair = [&](int a, int b) { return a >= 0 && b >= 0 ? passage_mm_[size_t(a) * n + size_t(b)] : 0.0; };
  double L = pair(end, other);
  for (int j = 0; j < chord.n; ++j) L = std::max(L, pair(end, chord.material[j]));
  return L;
}

// The chord's shares with each end's material counting a passage of `passage` mm and the chord
// `along` mm (passage_share), renormalised over the materials that carry the spatial transport.
SpatialTransport::Chord SpatialTransport::with_passages(const Chord& chord, const int* ends, int n_ends, double passage,
                                                        double along) const {
  if (!(n_ends * passage + along > 0)) return chord;
  Chord c = chord;
  int in_m[Chord::kMax] = {};
  for (int i = 0; i < n_ends; ++i) {
    if (!spatial_material(ends[i])) continue;
    int j = 0;
    while (j < c.n && c.material[j] != ends[i]) ++j;
    if (j == c.n) {
      if (c.n == Chord::kMax) continue;
      c.material[c.n] = ends[i];
      c.share[c.n++] = 0.0;
    }
    ++in_m[j];
  }
  double sum = 0;
  for (int j = 0; j < c.n; ++j) sum += c.share[j] = passage_share(c.share[j], in_m[j], n_ends, passage, along);
  for (int j = 0; j < c.n; ++j) c.share[j] /= sum;
  return c;
}

// Per lane, the factor by which the materials the fluorescence's two legs cross change what the
// emission point's material alone gives (docs/layered-tissue.md, "Regions and lateral transport"):
// each leg's Green's function (its slice's fluence times its lateral density) of every crossed
// material over the emission point's, raised to the crossed share of the leg: the emission leg
// x_m -> x_o at the lane's wavelength and the viewer's cosine, the excitation leg x_i -> x_m at LED
// group `group`'s light and the light's cosine mu_i at the entry. One where the legs stay in x_m's
// material.
void SpatialTransport::fluorescent_crossing(const Vertex& v, const Entry& e, int group, double mu_i, double* out) const {
  for (int k = 0; k < kLanes; ++k) out[k] = 1.0;
  // Most entries stay in one material (always without regions): nothing to look up.
  auto crosses = [&](const Chord& c) {
    for (int j = 0; j < c.n; ++j)
      if (c.material[j] != e.material && c.share[j] > 0) return true;
    return false;
  };
  if (!crosses(e.chord) && !crosses(e.ex_chord)) return;
  const std::vector<double>& depths = leg_depth_edges();
  const double z_mm = 0.5 * (depths[size_t(e.z)] + depths[size_t(e.z) + 1]);
  const Chord em_leg = leg_shares(e.chord, v.xo.material, e.material, e.rho_m, z_mm);
  const Chord ex_leg = leg_shares(e.ex_chord, e.xi.material, e.material, e.rho_i, z_mm);
  const SpatialStack& Sm = *t_.materials[e.material].stack.spatial;
  const auto co_m = Sm.cosines(v.mu_o), ci_m = Sm.cosines(mu_i);
  const double ex_m = Sm.excitation_fluence(group, ci_m, e.z) * Sm.excitation_density(group, ci_m, e.z, e.rho_i);
  for (int j = 0; j < ex_leg.n; ++j) {
    const int mj = ex_leg.material[j];
    if (mj == e.material || !(ex_leg.share[j] > 0)) continue;
    const SpatialStack& Sj = *t_.materials[mj].stack.spatial;
    const auto ci = Sj.cosines(mu_i);
    const double ex = Sj.excitation_fluence(group, ci, e.z) * Sj.excitation_density(group, ci, e.z, e.rho_i);
    const double ratio = ex_m > 0 ? std::pow(ex / ex_m, ex_leg.share[j]) : 0.0;
    for (int k = 0; k < kLanes; ++k) out[k] *= ratio;
  }
  for (int j = 0; j < em_leg.n; ++j) {
    const int mj = em_leg.material[j];
    if (mj == e.material || !(em_leg.share[j] > 0)) continue;
    const SpatialStack& Sj = *t_.materials[mj].stack.spatial;
    const auto co = Sj.cosines(v.mu_o);
    for (int k = 0; k < kLanes; ++k) {
      if (v.p.beta[k] == 0 || out[k] == 0) continue;
      const int em = v.p.wl[k];
      const double own = Sm.emission_fluence(co_m, em, e.z) * Sm.emission_density(co_m, em, e.z, e.rho_m);
      const double other = Sj.emission_fluence(co, em, e.z) * Sj.emission_density(co, em, e.z, e.rho_m);
      out[k] *= own > 0 ? std::pow(other / own, em_leg.share[j]) : 0.0;
    }
  }
}

// The direct fluorescence per lane that a material's stack sends from the LED point of `ls` to the
// viewer through depth slice e.z, emission leg e.rho_m and excitation leg `rho_i` (1/mm^4 of the
// two displacements, times the light's geometry term). Zero where the stack does not fluoresce.
void SpatialTransport::fluorescent_values(const Vertex& v, const MaterialTables& m, const Entry& e, const LightSample& ls,
                                          double rho_i, double* f) const {
  const SpatialStack& S = *m.stack.spatial;
  const StackResponse& R = *m.stack.response;
  for (int k = 0; k < kLanes; ++k) f[k] = 0;
  if (!ls.valid || !S.fluorescent || R.direct.empty()) return;
  const auto a = R.weights(v.mu_o), b = R.weights(ls.wi.z);
  const auto ci = S.cosines(ls.wi.z);
  const double ex = S.excitation_density(ls.group, ci, e.z, rho_i) * ls.g;
  if (!(ex > 0)) return;
  for (int k = 0; k < kLanes; ++k) {
    if (v.p.beta[k] == 0) continue;
    const int em = v.p.wl[k];
    const double total = S.slice_sum(ls.group, v.co, ci, em);
    if (!(total > 0)) continue;
    const double depth = S.slice_weight(ls.group, v.co, ci, em, e.z) / total;
    f[k] = R.direct_at(ls.group, a, b, em) * depth * S.emission_density(v.co, em, e.z, e.rho_m) * ex;
  }
}

// Next-event estimation from the entry point, for the chosen strategy's lanes: what the spatial
// transport sends from the LED through x_i, minus what x_o's own material would send through the
// same displacements from the anchor's connection at x_o (whose expectation, the anchor, was added
// in full): with even light on one material the two cancel and only the light's change across the
// spread is left to sample.
void SpatialTransport::entry_light(Vertex& v, Entry& e, RayCounts& counts, RayLog* log) const {
  if (v.light < 0) return;
  const LightSample ls = connect(v, e.xi, Frame(e.xi.ns), counts, log);
  const LightSample& lo = v.at_o;
  if (!ls.valid && !lo.valid) return;
  const float* shape = t_.light_shape[v.group].data();
  double f[kLanes], h[kLanes];
  if (!e.fluorescent) {
    const double cont = (1.0 - v.p_spec) * cosine_hemisphere_pdf(ls.wi.z) * e.q_cont / e.q_nee;
    const double mis = ls.pdf_solid > 0 ? power_heuristic(ls.pdf_solid, cont) : 1.0;
    if (ls.valid) elastic_values(v, e, ls.wi.z, f);
    if (lo.valid) {
      const auto a = v.R.weights(v.mu_o), b = v.R.weights(lo.wi.z);
      for (int k = 0; k < kLanes; ++k)
        h[k] = v.p.beta[k] == 0 ? 0.0 : v.R.elastic_at(a, b, v.p.wl[k]) * v.S.elastic_density(v.co, v.p.wl[k], e.r_mm);
    }
    for (int k = 0; k < kLanes; ++k) {
      if (v.p.beta[k] == 0) continue;
      const double here = ls.valid ? f[k] * ls.g * mis : 0.0, there = lo.valid ? h[k] * lo.g * v.w_o : 0.0;
      v.p.add(k, v.p.beta[k] * (here - there) * shape[v.p.wl[k]] / (e.pdf * e.q_nee));
    }
    return;
  }
  fluorescent_values(v, t_.materials[e.material], e, ls, e.rho_i, f);
  fluorescent_values(v, v.mt, e, lo, e.rho_i, h);
  if (ls.valid) {
    double x[kLanes];
    fluorescent_crossing(v, e, ls.group, ls.wi.z, x);
    for (int k = 0; k < kLanes; ++k) f[k] *= x[k];
  }
  for (int k = 0; k < kLanes; ++k) {
    const double add = v.p.beta[k] * (f[k] - h[k]) / (e.pdf_m * e.pdf_i * e.q_nee);
    v.p.L[k] += float(add);
    v.p.Lf[k] += float(add);
  }
}

// The continuation from the entry point (cosine lobe), carrying the strategy's lanes.
SpatialScatter SpatialTransport::continue_at_entry(Vertex& v, Entry& e, Rng& rng) const {
  SpatialScatter c;
  const glm::dvec3 wi = sample_cosine_hemisphere(rng.next_double(), rng.next_double());
  const Frame fi(e.xi.ns);
  const glm::dvec3 wi_w = fi.to_world(wi);
  if (!(wi.z > 0) || glm::dot(wi_w, e.xi.ng) <= 0) return c;
  const double pdf = (1.0 - v.p_spec) * cosine_hemisphere_pdf(wi.z);
  const MaterialTables& m = t_.materials[e.material];
  const SpatialStack& S = *m.stack.spatial;
  const StackResponse& R = *m.stack.response;
  const auto a = R.weights(v.mu_o), b = R.weights(wi.z);
  const auto ci = S.cosines(wi.z);
  const double geo = wi.z / (pdf * e.q_cont);
  const double legs = e.fluorescent ? S.excitation_density(v.group, ci, e.z, e.rho_i) / (e.pdf_m * e.pdf_i) : 0.0;
  double fe[kLanes];
  if (!e.fluorescent) elastic_values(v, e, wi.z, fe);
  else fluorescent_crossing(v, e, v.group, wi.z, fe);
  bool any = false;
  for (int k = 0; k < kLanes; ++k) {
    if (v.p.beta[k] == 0) continue;
    const int em = v.p.wl[k];
    double f = 0;
    if (!e.fluorescent) {
      f = fe[k] / e.pdf;
      v.p.rerad_prev[k] = false;
    } else if (!R.fluor.empty()) {
      const double total = S.slice_sum(v.group, v.co, ci, em);
      if (total > 0)
        f = R.fluor_sum_at(a, b, em) * S.slice_weight(v.group, v.co, ci, em, e.z) / total *
            S.emission_density(v.co, em, e.z, e.rho_m) * legs * fe[k];
      if (f > 0) {
        v.p.wl[k] = R.sample_excitation(a, b, em, rng.next_double(), rng.next_float());
        v.p.fl[k] = true;
        v.p.rerad_prev[k] = true;  // next-event estimation summed the LED's direct excitation
      }
    }
    v.p.beta[k] = float(v.p.beta[k] * f * geo);
    any = any || v.p.beta[k] > 0;
  }
  if (!any) return c;
  c.ok = true;
  c.from = e.xi;
  c.wi_world = wi_w;
  c.pdf = e.fluorescent ? 0.0 : pdf * e.q_cont / e.q_nee;  // as the next-event MIS weighs it
  return c;
}

// The continuation by the top interface at x_o: the Fresnel mirror (smooth) or the GGX lobe (rough).
SpatialScatter SpatialTransport::continue_at_top(Vertex& v, Rng& rng) const {
  SpatialScatter c;
  c.from = v.xo;
  c.reflected = true;
  for (int k = 0; k < kLanes; ++k) v.p.rerad_prev[k] = false;
  if (v.smooth) {  // probability F, value F: weight 1
    c.ok = true;
    c.wi_world = v.frame.to_world(glm::dvec3(-v.wo.x, -v.wo.y, v.wo.z));
    return c;
  }
  const GgxCoating& lobe = v.mt.stack.top_lobe;
  const glm::dvec3 wi = lobe.sample(v.wo, rng.next_double(), rng.next_double());
  if (!(wi.z > 0)) return c;
  const double pdf = v.p_spec * lobe.pdf(v.wo, wi);
  if (!(pdf > 0)) return c;
  const double w = v.mt.stack.top.reflection(v.wo, wi) * wi.z / pdf;
  for (int k = 0; k < kLanes; ++k) v.p.beta[k] = float(v.p.beta[k] * w);
  c.ok = true;
  c.wi_world = v.frame.to_world(wi);
  c.pdf = pdf;
  return c;
}

SpatialScatter SpatialTransport::scatter(const SurfacePoint& xo, unsigned geom, const Frame& frame, const glm::dvec3& wo,
                                         const MaterialTables& mt, PathLanes& p, Rng& rng, RayCounts& counts,
                                         RayLog* log) const {
  const StackTables& st = mt.stack;
  Vertex v{xo, geom, frame, wo, mt, p, *st.spatial, *st.response};
  v.mu_o = std::clamp(wo.z, 1e-4, 1.0);
  v.smooth = st.top.smooth();
  v.p_spec = v.smooth ? fresnel_dielectric(v.mu_o, st.layers[0].ior / st.ambient_ior)
                      : std::clamp(st.top_lobe.specular_albedo(v.mu_o), 0.05, 0.95);
  // One LED for the vertex, chosen by power, and one point on it (led_seed) for every connection;
  // its cosine at x_o stands in for the one at x_i where the entry is planned.
  if (!scene_.lights.empty()) {
    v.light = t_.light_select.sample(rng.next_double());
    v.group = t_.light_group[v.light];
    v.led_seed = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
    const glm::dvec3 to = glm::normalize(scene_.lights[v.light].position - xo.p);
    v.mu_i_proxy = std::clamp(glm::dot(to, xo.ns), 0.05, 1.0);
  }
  v.co = v.S.cosines(v.mu_o);
  v.ci_proxy = v.S.cosines(v.mu_i_proxy);
  // Which entry the path continues from (if not from the top), then which strategies run.
  const Plan pl = plan(v);
  anchor(v, pl, counts, log);
  top_light(v);
  const bool top = rng.next_double() < v.p_spec;
  const bool cont_fl = !top && rng.next_double() < pl.cont_fl;
  const bool cont_el = !top && !cont_fl;
  Entry entries[2];
  for (int f = 0; f < 2; ++f) {
    const bool fl = f == 1;
    const double c = (1.0 - v.p_spec) * (fl ? pl.cont_fl : 1.0 - pl.cont_fl), run = fl ? pl.run_fl : pl.run_el;
    const bool chosen = fl ? cont_fl : cont_el;
    if (!chosen && !(rng.next_double() < run)) continue;
    Entry& e = entries[f];
    e = fl ? sample_fluorescent(v, rng, counts) : sample_elastic(v, rng, counts);
    e.q_nee = c + (1.0 - c) * run;
    e.q_cont = fl ? pl.cont_fl : 1.0 - pl.cont_fl;
    if (e.found) entry_light(v, e, counts, log);
  }
  if (top) return continue_at_top(v, rng);
  Entry& e = entries[cont_fl ? 1 : 0];
  if (!e.found || !(e.q_cont > 0)) return {};
  return continue_at_entry(v, e, rng);
}

}  // namespace ofl
