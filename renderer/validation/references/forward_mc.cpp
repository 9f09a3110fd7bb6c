// The independent forward photon Monte Carlo (see forward_mc.h).
#include "renderer/validation/references/forward_mc.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "renderer/render/trace/rng.h"

namespace ofl {

namespace {

constexpr double kPiMc = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

// One layer of one column, ready for forward photons.
struct FLayer {
  double top = 0, bottom = 0, n = 1, g = 0;
  std::vector<double> mut, mus, kappa;  // per bin: total attenuation, scattering, re-emission
  std::vector<double> em_cdf;           // [ex * nbins + em] running sum over em of emit(em <- ex), normalised
};

struct FColumn {
  std::vector<FLayer> layers;
  double n_above = 1, n_below = 1;
  bool open_bottom = false;
  int layer_at(double z) const {
    for (size_t l = 0; l < layers.size(); ++l)
      if (z < layers[l].bottom) return int(l);
    return int(layers.size()) - 1;
  }
  // The vertical passage out through the top, made once per layer and bin (up_transmission):
  // just below the top face of layer l, the chance to leave through the top (up_out) and to come
  // back down (up_back); just above its bottom face, the chance to come back up (down_back).
  int nbins = 0;
  std::vector<double> up_out, up_back, down_back;  // [l * nbins + bin]
  void tabulate_vertical(int n);
  double up_transmission(int l, double z, int wl) const;
};

// Reflectance of a face at normal incidence.
double fresnel_normal(double n1, double n2) {
  const double r = (n1 - n2) / (n1 + n2);
  return r * r;
}

// Light bouncing between a face of reflectance r and what lies beyond it, which sends back
// `beyond`: the reflectance of the two together, seen from the face's near side.
double reflect_with_face(double r, double beyond) { return r + (1.0 - r) * (1.0 - r) * beyond / (1.0 - r * beyond); }

void FColumn::tabulate_vertical(int n) {
  const int L = int(layers.size());
  nbins = n;
  up_out.assign(size_t(L) * n, 0.0);
  up_back.assign(size_t(L) * n, 0.0);
  down_back.assign(size_t(L) * n, 0.0);
  auto through = [&](int j, int w) { return std::exp(-layers[j].mut[w] * (layers[j].bottom - layers[j].top)); };
  for (int w = 0; w < n; ++w) {
    double tt = 1.0 - fresnel_normal(n_above, layers[0].n), rb = 1.0 - tt;
    for (int l = 0; l < L; ++l) {
      if (l > 0) {  // through layer l - 1, then the face between it and layer l
        const double t = through(l - 1, w), r = fresnel_normal(layers[l - 1].n, layers[l].n);
        tt *= t;
        rb *= t * t;
        tt = (1.0 - r) * tt / (1.0 - r * rb);
        rb = reflect_with_face(r, rb);
      }
      up_out[size_t(l) * n + w] = tt;
      up_back[size_t(l) * n + w] = rb;
    }
    double rd = open_bottom ? fresnel_normal(layers.back().n, n_below) : 0.0;
    for (int l = L - 1; l >= 0; --l) {
      if (l < L - 1) {  // through layer l + 1, then the face between layer l and it
        const double t = through(l + 1, w);
        rd = reflect_with_face(fresnel_normal(layers[l].n, layers[l + 1].n), rd * t * t);
      }
      down_back[size_t(l) * n + w] = rd;
    }
  }
}

// The chance that light at depth z of layer l going straight up leaves through the top, with every
// incoherent bounce between the column's index steps (all at normal incidence) summed.
double FColumn::up_transmission(int l, double z, int wl) const {
  const size_t i = size_t(l) * nbins + wl;
  const double tz = std::exp(-layers[l].mut[wl] * (z - layers[l].top));
  const double tt = up_out[i] * tz, rb = up_back[i] * tz * tz;
  double rd = down_back[i];
  if (rd > 0) {
    const double tb = std::isfinite(layers[l].bottom) ? std::exp(-layers[l].mut[wl] * (layers[l].bottom - z)) : 0.0;
    rd *= tb * tb;
  }
  return tt / (1.0 - rb * rd);
}

FColumn column_from(const StackTables& st, int n) {
  if (st.bottom == StackBottom::kBase) throw std::invalid_argument("forward Monte Carlo: an opaque base is not modelled");
  FColumn c;
  c.n_above = st.ambient_ior;
  c.n_below = st.below_ior;
  c.open_bottom = st.bottom == StackBottom::kOpen;
  for (const StackLayerTables& L : st.layers) {
    FLayer f;
    f.top = L.top;
    f.bottom = L.bottom;
    f.n = L.ior;
    f.g = L.g;
    f.mut.assign(n, 0.0);
    f.mus.assign(n, 0.0);
    f.kappa.assign(n, 0.0);
    f.em_cdf.assign(size_t(n) * n, 0.0);
    for (int w = 0; w < n; ++w) {
      double a = L.mua[w];
      for (const auto& fl : L.fluors) a += fl.absorb[w];
      f.mus[w] = L.mus[w];
      f.mut[w] = a + L.mus[w];
    }
    for (int ex = 0; ex < n; ++ex) {
      double acc = 0;
      for (int em = 0; em < n; ++em) {
        for (const auto& fl : L.fluors)
          if (!fl.emit.empty()) acc += fl.emit[size_t(em) * n + ex];
        f.em_cdf[size_t(ex) * n + em] = acc;
      }
      f.kappa[ex] = acc;
      if (acc > 0)
        for (int em = 0; em < n; ++em) f.em_cdf[size_t(ex) * n + em] /= acc;
    }
    c.layers.push_back(std::move(f));
  }
  c.tabulate_vertical(n);
  return c;
}

double fresnel(double cos_i, double n1, double n2) {
  const double eta = n1 / n2, s2 = eta * eta * (1.0 - cos_i * cos_i);
  if (s2 >= 1.0) return 1.0;
  const double ct = std::sqrt(1.0 - s2);
  const double rs = (n1 * cos_i - n2 * ct) / (n1 * cos_i + n2 * ct), rp = (n1 * ct - n2 * cos_i) / (n1 * ct + n2 * cos_i);
  return 0.5 * (rs * rs + rp * rp);
}

struct Photon {
  double x = 0, y = 0, z = 0;       // z: depth below the top face, mm
  double dx = 0, dy = 0, dz = 1;    // dz > 0: going deeper
  int wl = 0;
  double w = 1;
  bool fluorescent = false;
};

// A direction after Henyey-Greenstein scattering of (dx, dy, dz) with anisotropy g.
void scatter_hg(Photon& p, double g, Rng& rng) {
  double c;
  if (std::abs(g) < 1e-6) {
    c = 2.0 * rng.next_double() - 1.0;
  } else {
    const double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * rng.next_double());
    c = std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
  }
  const double sn = std::sqrt(std::max(0.0, 1.0 - c * c)), phi = 2.0 * kPiMc * rng.next_double();
  const double cp = std::cos(phi), sp = std::sin(phi);
  if (std::abs(p.dz) > 0.99999) {
    const double sign = p.dz > 0 ? 1.0 : -1.0;
    p.dx = sn * cp;
    p.dy = sn * sp;
    p.dz = sign * c;
    return;
  }
  const double t = std::sqrt(1.0 - p.dz * p.dz);
  const double nx = sn * (p.dx * p.dz * cp - p.dy * sp) / t + p.dx * c;
  const double ny = sn * (p.dy * p.dz * cp + p.dx * sp) / t + p.dy * c;
  const double nz = -sn * cp * t + p.dz * c;
  const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
  p.dx = nx / len;
  p.dy = ny / len;
  p.dz = nz / len;
}

// Henyey-Greenstein density (per steradian) of turning by an angle of cosine mu.
double hg_density(double g, double mu) {
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPiMc * d * std::sqrt(d));
}

void isotropic(Photon& p, Rng& rng) {
  const double c = 2.0 * rng.next_double() - 1.0, s = std::sqrt(std::max(0.0, 1.0 - c * c)), phi = 2.0 * kPiMc * rng.next_double();
  p.dx = s * std::cos(phi);
  p.dy = s * std::sin(phi);
  p.dz = c;
}

class Simulator {
 public:
  Simulator(const ForwardSetup& s) : s_(s), out_(column_from(*s.outside.st, s.n)) {
    if (s.radius_mm > 0) {
      in_ = column_from(*s.inside.st, s.n);
      check_matched();
    }
  }
  void run(Rng& rng, ForwardTally& t) const;

 private:
  const FColumn& column(const Photon& p) const {
    return s_.radius_mm > 0 && p.x * p.x + p.y * p.y < s_.radius_mm * s_.radius_mm ? in_ : out_;
  }
  void check_matched() const;
  double wall_distance(const Photon& p) const;
  void trace(Photon p, Rng& rng, ForwardTally& t, std::vector<Photon>& children) const;
  bool collide(Photon& p, const FColumn& c, int l, Rng& rng, ForwardTally& t, std::vector<Photon>& children) const;
  void tally_normal(const Photon& p, const FColumn& c, int l, double density, ForwardTally& t) const;
  enum class Crossing { kLeft, kReflected, kRefracted };
  Crossing boundary(Photon& p, const FColumn& c, int l, Rng& rng, ForwardTally& t) const;
  int ring_of(const Photon& p) const;  // the tally ring p is over, -1 outside them
  void tally_exit(const Photon& p, double cos_air, ForwardTally& t) const;

  const ForwardSetup& s_;
  FColumn out_, in_;
};

void Simulator::check_matched() const {
  // The index as a function of depth must be the same in both columns (the wall does not refract).
  std::vector<double> z;
  for (const auto* c : {&out_, &in_})
    for (const auto& L : c->layers) {
      z.push_back(L.top);
      if (std::isfinite(L.bottom)) z.push_back(L.bottom);
    }
  for (double d : z)
    for (double probe : {d + 1e-9, std::max(0.0, d - 1e-9)}) {
      const auto& a = out_.layers[out_.layer_at(probe)];
      const auto& b = in_.layers[in_.layer_at(probe)];
      if (a.n != b.n) throw std::invalid_argument("forward Monte Carlo: the cylinder's refractive index differs from its surroundings");
    }
}

double Simulator::wall_distance(const Photon& p) const {
  const double a = s_.radius_mm;
  if (!(a > 0)) return kInf;
  const double A = p.dx * p.dx + p.dy * p.dy;
  if (A < 1e-18) return kInf;
  const double B = 2.0 * (p.x * p.dx + p.y * p.dy), C = p.x * p.x + p.y * p.y - a * a;
  const double disc = B * B - 4.0 * A * C;
  if (disc < 0) return kInf;
  const double q = std::sqrt(disc);
  const double t1 = (-B - q) / (2.0 * A), t2 = (-B + q) / (2.0 * A);
  const double eps = 1e-9;
  if (t1 > eps) return t1;
  if (t2 > eps) return t2;
  return kInf;
}

int Simulator::ring_of(const Photon& p) const {
  const double r = std::hypot(p.x, p.y);
  const auto& e = s_.ring_edges;
  if (e.size() < 2 || r < e.front() || r >= e.back()) return -1;
  return int(std::upper_bound(e.begin(), e.end(), r) - e.begin()) - 1;
}

void Simulator::tally_exit(const Photon& p, double cos_air, ForwardTally& t) const {
  const int ring = ring_of(p);
  if (ring < 0) return;
  const size_t i = size_t(ring) * s_.n + p.wl;
  (p.fluorescent ? t.fluor : t.elastic)[i] += p.w;
  if (cos_air > s_.cone_cos) (p.fluorescent ? t.fluor_cone : t.elastic_cone)[i] += p.w;
  if (cos_air > s_.narrow_cos) (p.fluorescent ? t.fluor_narrow : t.elastic_narrow)[i] += p.w;
}

// The local estimate of the light leaving along the normal (forward_mc.h): the photon, at depth
// p.z of layer l of column c, turns straight up with `density` per steradian in the layer.
void Simulator::tally_normal(const Photon& p, const FColumn& c, int l, double density, ForwardTally& t) const {
  const int ring = ring_of(p);
  if (ring < 0) return;
  const double solid_angle = (c.n_above / c.layers[l].n) * (c.n_above / c.layers[l].n);
  const double v = p.w * density * c.up_transmission(l, p.z, p.wl) * solid_angle;
  (p.fluorescent ? t.fluor_normal : t.elastic_normal)[size_t(ring) * s_.n + p.wl] += v;
}

// At a horizontal face of layer l of column c: reflect, refract into the next layer, or leave
// (top: tallied; bottom: lost).
Simulator::Crossing Simulator::boundary(Photon& p, const FColumn& c, int l, Rng& rng, ForwardTally& t) const {
  const bool up = p.dz < 0;
  const int next = up ? l - 1 : l + 1;
  const bool leaves = up ? l == 0 : l + 1 == int(c.layers.size());
  const double n1 = c.layers[l].n;
  const double n2 = leaves ? (up ? c.n_above : c.n_below) : c.layers[next].n;
  if (leaves && !up && !c.open_bottom) return Crossing::kLeft;  // semi-infinite: never reached
  const double ci = std::abs(p.dz);
  if (n1 != n2 && rng.next_double() < fresnel(ci, n1, n2)) {
    p.dz = -p.dz;
    return Crossing::kReflected;
  }
  if (n1 != n2) {  // Snell: the tangential part scales by n1 / n2
    const double eta = n1 / n2, ct = std::sqrt(std::max(0.0, 1.0 - eta * eta * (1.0 - ci * ci)));
    p.dx *= eta;
    p.dy *= eta;
    p.dz = (up ? -1.0 : 1.0) * ct;
  }
  if (leaves) {
    if (up) tally_exit(p, std::abs(p.dz), t);
    return Crossing::kLeft;
  }
  return Crossing::kRefracted;
}

// One photon until it leaves or is rouletted away; its fluorescence children go to `children`.
// Exponential flights are memoryless, so a flight that reaches a boundary simply ends there and the
// next one starts fresh in the new layer or column.
void Simulator::trace(Photon p, Rng& rng, ForwardTally& t, std::vector<Photon>& children) const {
  for (int guard = 0; guard < 10000000; ++guard) {
    const FColumn& c = column(p);
    const int l = c.layer_at(p.z);
    const FLayer& L = c.layers[l];
    const double to_plane = p.dz > 0 ? (L.bottom - p.z) / p.dz : p.dz < 0 ? (p.z - L.top) / -p.dz : kInf;
    const double to_wall = wall_distance(p);
    const double tb = std::min(to_plane, to_wall);
    const double mut = L.mut[p.wl];
    const double d = mut > 0 ? -std::log(1.0 - rng.next_double()) / mut : kInf;
    if (d < tb) {
      p.x += d * p.dx;
      p.y += d * p.dy;
      p.z = std::clamp(p.z + d * p.dz, L.top, L.bottom);
      if (!collide(p, c, l, rng, t, children)) return;
      continue;
    }
    if (!std::isfinite(tb)) return;  // horizontal in a clear semi-infinite layer
    p.x += tb * p.dx;
    p.y += tb * p.dy;
    p.z += tb * p.dz;
    if (to_wall < to_plane) {  // into the other column at the same depth: nudge across the wall
      p.x += 1e-9 * p.dx;
      p.y += 1e-9 * p.dy;
      continue;
    }
    const bool down = p.dz > 0;
    const double face = down ? L.bottom : L.top;
    const Crossing x = boundary(p, c, l, rng, t);
    if (x == Crossing::kLeft) return;
    // Just inside the layer it travels in now: the same one after a reflection, the next one after
    // a refraction (layer_at gives a face's depth to the layer below it).
    const bool into_upper = (x == Crossing::kReflected) == down;
    p.z = into_upper ? std::nextafter(face, -kInf) : face;
    if (p.z < 0) p.z = 0;
  }
}

// A collision, analog: the photon scatters with probability mu_s / mu_t, else it is absorbed; an
// absorbed excitation photon always leaves a fluorescence child carrying the probability kappa / mu_a
// that the absorption re-emits (at a bin drawn from the layer's re-emission), isotropic. Returns
// whether the photon goes on.
bool Simulator::collide(Photon& p, const FColumn& c, int l, Rng& rng, ForwardTally& t, std::vector<Photon>& children) const {
  const FLayer& L = c.layers[l];
  if (rng.next_double() * L.mut[p.wl] < L.mus[p.wl]) {
    tally_normal(p, c, l, hg_density(L.g, -p.dz), t);  // up is (0, 0, -1)
    scatter_hg(p, L.g, rng);
    return true;
  }
  const double mua = L.mut[p.wl] - L.mus[p.wl];
  if (s_.fluorescence && !p.fluorescent && L.kappa[p.wl] > 0 && mua > 0) {
    Photon ch = p;
    ch.fluorescent = true;
    ch.w = p.w * L.kappa[p.wl] / mua;
    const double* cdf = &L.em_cdf[size_t(p.wl) * s_.n];
    ch.wl = std::min(int(std::upper_bound(cdf, cdf + s_.n, rng.next_double()) - cdf), s_.n - 1);
    isotropic(ch, rng);
    tally_normal(ch, c, l, 1.0 / (4.0 * kPiMc), t);
    children.push_back(ch);
  }
  return false;
}

void Simulator::run(Rng& rng, ForwardTally& t) const {
  // Source bin and entry point.
  const auto& src = s_.source;
  double total = 0;
  for (double v : src) total += v;
  double u = rng.next_double() * total;
  int wl = 0;
  for (; wl + 1 < s_.n; ++wl) {
    if (u < src[wl]) break;
    u -= src[wl];
  }
  Photon p;
  p.wl = wl;
  if (s_.half_mm > 0) {
    const double f = s_.focus_mm;
    if (f > 0 && rng.next_double() < 0.5) {
      const double r = f * std::sqrt(rng.next_double()), phi = 2.0 * kPiMc * rng.next_double();
      p.x = r * std::cos(phi);
      p.y = r * std::sin(phi);
    } else {
      p.x = (2.0 * rng.next_double() - 1.0) * s_.half_mm;
      p.y = (2.0 * rng.next_double() - 1.0) * s_.half_mm;
    }
    if (f > 0) {
      const double square = 4.0 * s_.half_mm * s_.half_mm;
      const double inside = p.x * p.x + p.y * p.y < f * f ? 1.0 / (kPiMc * f * f) : 0.0;
      p.w = (1.0 / square) / (0.5 / square + 0.5 * inside);
    }
  }
  const double th = s_.theta_deg * kPiMc / 180.0, ci = std::cos(th);
  const FColumn& c = column(p);
  const double n0 = c.n_above, n1 = c.layers[0].n;
  if (rng.next_double() < fresnel(ci, n0, n1)) return;  // specular reflection
  const double eta = n0 / n1;
  p.dx = eta * std::sin(th);
  p.dy = 0;
  p.dz = std::sqrt(std::max(0.0, 1.0 - p.dx * p.dx));
  std::vector<Photon> children;
  trace(p, rng, t, children);
  for (size_t i = 0; i < children.size(); ++i) trace(children[i], rng, t, children);
}

}  // namespace

void ForwardTally::add(const ForwardTally& o) {
  photons += o.photons;
  auto acc = [](std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() < b.size()) a.resize(b.size(), 0.0);
    for (size_t i = 0; i < b.size(); ++i) a[i] += b[i];
  };
  acc(elastic, o.elastic);
  acc(fluor, o.fluor);
  acc(elastic_cone, o.elastic_cone);
  acc(fluor_cone, o.fluor_cone);
  acc(elastic_narrow, o.elastic_narrow);
  acc(fluor_narrow, o.fluor_narrow);
  acc(elastic_normal, o.elastic_normal);
  acc(fluor_normal, o.fluor_normal);
}

// Every tally of t zeroed, `cells` long.
void clear_tally(ForwardTally& t, size_t cells) {
  for (auto* v : {&t.elastic, &t.fluor, &t.elastic_cone, &t.fluor_cone, &t.elastic_narrow, &t.fluor_narrow, &t.elastic_normal,
                  &t.fluor_normal})
    v->assign(cells, 0.0);
}

ForwardTally run_forward_mc(const ForwardSetup& s, long long photons, uint64_t seed) {
  const Simulator sim(s);
  const size_t cells = (s.ring_edges.size() > 1 ? s.ring_edges.size() - 1 : 0) * size_t(s.n);
  const long long block = 2048, blocks = (photons + block - 1) / block;
  std::vector<ForwardTally> part(blocks);
  tbb::parallel_for((long long)0, blocks, [&](long long b) {
    ForwardTally& t = part[b];
    clear_tally(t, cells);
    const long long end = std::min(photons, (b + 1) * block);
    for (long long i = b * block; i < end; ++i) {
      Rng rng(seed, Rng::stream_for(0x46574D43ULL, uint64_t(i)));
      sim.run(rng, t);
    }
    t.photons = end - b * block;
  });
  ForwardTally out;
  clear_tally(out, cells);
  for (const auto& t : part) out.add(t);
  return out;
}

}  // namespace ofl
