// The render-time tables of the spatial transport (see spatial_tables.h).
#include "renderer/render/spatial/spatial_tables.h"

#include <algorithm>
#include <cmath>

#include "renderer/render/stack/stack_fill.h"

namespace ofl {

namespace {

constexpr double kSearchMass = 0.999;  // the search radius holds this much of every profile

// The first ring (index) beyond which no profile among `count` of R rings has more than
// 1 - kSearchMass of its mass left.
int search_rings(const std::vector<float>& cdf, size_t count, int R) {
  int j_max = 1;
  for (size_t p = 0; p < count; ++p) {
    const float* c = &cdf[p * R];
    int j = int(std::lower_bound(c, c + R, float(kSearchMass)) - c) + 1;
    j_max = std::max(j_max, std::min(j, R));
  }
  return j_max;
}

// Copies `count` profiles of R rings, cut after `keep` rings and renormalised.
void cut_profiles(const std::vector<float>& mass, size_t count, int R, int keep, std::vector<float>& out_mass,
                  std::vector<float>& out_cdf) {
  out_mass.assign(count * R, 0.0f);
  out_cdf.assign(count * R, 1.0f);
  std::vector<double> t(R);
  for (size_t p = 0; p < count; ++p) {
    for (int j = 0; j < R; ++j) t[j] = j < keep ? mass[p * R + j] : 0.0;
    radial::normalise(R, t.data(), &out_mass[p * R], &out_cdf[p * R]);
  }
}

int slice_of_bin(double lo, double hi) {
  const auto& e = leg_depth_edges();
  const double mid = 0.5 * (lo + hi);
  int z = int(std::upper_bound(e.begin(), e.end(), mid) - e.begin()) - 1;
  return std::clamp(z, 0, int(e.size()) - 2);
}

// The depth weights of direct fluorescence per LED group (spatial_tables.h).
void fill_slice_weights(const StackTables& st, const std::vector<std::vector<float>>& shapes, SpatialStack& s) {
  const StackProfiles& p = *s.prof;
  const DepthBins bins(st);
  const int B = bins.size(), n = s.n, C = s.C, Z = s.Z;
  const auto sigma = layer_emission(st, n);
  std::vector<int> slice(B);
  std::vector<double> cam(B);
  for (int b = 0; b < B; ++b) {
    slice[b] = slice_of_bin(bins.lo[b], bins.hi[b]);
    const double ratio = st.ambient_ior / st.layers[bins.layer[b]].ior;
    cam[b] = ratio * ratio / (bins.hi[b] - bins.lo[b]);
  }
  auto fluence = [&](int c, int wl, int b) { return double(p.fine_fluence[(size_t(c) * n + wl) * B + b]); };
  s.slice_c.assign(size_t(s.G) * C * C * n * Z, 0.0f);
  s.slice_total.assign(size_t(s.G) * C * C * n, 0.0f);
  std::vector<double> excite(size_t(C) * B);
  for (int g = 0; g < s.G; ++g)
    for (int em = 1; em < n; ++em) {
      // sum over ex of sigma_b(em <- ex) S(ex) Phi(b; c_i, ex), per light cosine and bin
      std::fill(excite.begin(), excite.end(), 0.0);
      for (int b = 0; b < B; ++b) {
        const auto& sg = sigma[bins.layer[b]];
        if (sg.empty()) continue;
        for (int ex = 0; ex < em; ++ex) {
          const double w = double(sg[size_t(em) * n + ex]) * shapes[g][ex];
          if (w == 0) continue;
          for (int ci = 0; ci < C; ++ci) excite[size_t(ci) * B + b] += w * fluence(ci, ex, b);
        }
      }
      for (int co = 0; co < C; ++co)
        for (int ci = 0; ci < C; ++ci) {
          float* out = &s.slice_c[s.slice_at(g, co, ci, em) * Z];
          double total = 0;
          for (int b = 0; b < B; ++b) {
            const double v = fluence(co, em, b) * cam[b] * excite[size_t(ci) * B + b];
            out[slice[b]] += float(v);
            total += v;
          }
          s.slice_total[s.slice_at(g, co, ci, em)] = float(total);
          if (total > 0) s.fluorescent = true;
        }
    }
}

// The excitation legs per LED group (spatial_tables.h).
void fill_excitation_legs(const StackTables& st, const std::vector<std::vector<float>>& shapes, SpatialStack& s) {
  const StackProfiles& p = *s.prof;
  const DepthBins bins(st);
  const int B = bins.size(), n = s.n, C = s.C, Z = s.Z, R = p.leg_rings.rings;
  std::vector<double> absorb(size_t(B) * n, 0.0);  // fluorophore absorption of each bin's layer
  for (int b = 0; b < B; ++b)
    for (const auto& f : st.layers[bins.layer[b]].fluors)
      for (int ex = 0; ex < n; ++ex) absorb[size_t(b) * n + ex] += f.absorb[ex];
  s.ex_mass.assign(size_t(s.G) * C * Z * R, 0.0f);
  s.ex_cdf.assign(size_t(s.G) * C * Z * R, 1.0f);
  s.ex_fluence.assign(size_t(s.G) * C * Z, 0.0f);
  std::vector<double> w(n), t(R);
  for (int g = 0; g < s.G; ++g)
    for (int c = 0; c < C; ++c)
      for (int z = 0; z < Z; ++z) {
        double wsum = 0, photons = 0, fluence = 0;
        for (int ex = 0; ex < n; ++ex) {
          photons += shapes[g][ex];
          fluence += shapes[g][ex] * p.leg_fluence[(size_t(c) * n + ex) * Z + z];
        }
        s.ex_fluence[(size_t(g) * C + c) * Z + z] = photons > 0 ? float(fluence / photons) : 0.0f;
        for (int ex = 0; ex < n; ++ex) {
          double a = 0;
          for (int b = 0; b < B; ++b)
            if (slice_of_bin(bins.lo[b], bins.hi[b]) == z)
              a += p.fine_fluence[(size_t(c) * n + ex) * B + b] * absorb[size_t(b) * n + ex];
          w[ex] = shapes[g][ex] * a;
          wsum += w[ex];
        }
        if (!(wsum > 0))  // no fluorophore absorbs the light here: the light's own spread stands in
          for (int ex = 0; ex < n; ++ex) w[ex] = shapes[g][ex] * p.leg_fluence[(size_t(c) * n + ex) * Z + z];
        std::fill(t.begin(), t.end(), 0.0);
        for (int ex = 0; ex < n; ++ex)
          if (w[ex] > 0)
            for (int j = 0; j < R; ++j) t[j] += w[ex] * s.leg_mass[s.leg_at(c, ex, z) + j];
        radial::normalise(R, t.data(), &s.ex_mass[s.ex_at(g, c, z)], &s.ex_cdf[s.ex_at(g, c, z)]);
      }
}

// Ring masses as densities per unit area.
void densities(const std::vector<float>& mass, const RadialRings& g, std::vector<float>& out) {
  out.resize(mass.size());
  for (size_t i = 0; i < mass.size(); ++i) out[i] = float(mass[i] / g.area(int(i % g.rings)));
}

}  // namespace

double SpatialStack::elastic_density(const Cosines& cw, int wl, double r_mm) const {
  const int j = el_rings().ring_of(r_mm);
  return j < 0 ? 0.0 : elastic_density_in(cw, wl, j);
}

void SpatialStack::slice_weights(int g, const Cosines& wo, const Cosines& wi, int em, double* out) const {
  for (int z = 0; z < Z; ++z) out[z] = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      const double w = wo.w[a] * wi.w[b];
      if (!(w > 0)) continue;
      const float* c = &slice_c[slice_at(g, wo.c[a], wi.c[b], em) * Z];
      for (int z = 0; z < Z; ++z) out[z] += w * c[z];
    }
}

double SpatialStack::slice_weight(int g, const Cosines& wo, const Cosines& wi, int em, int z) const {
  double v = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      if (wo.w[a] * wi.w[b] > 0) v += wo.w[a] * wi.w[b] * slice_c[slice_at(g, wo.c[a], wi.c[b], em) * Z + z];
  return v;
}

double SpatialStack::slice_sum(int g, const Cosines& wo, const Cosines& wi, int em) const {
  double v = 0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      if (wo.w[a] * wi.w[b] > 0) v += wo.w[a] * wi.w[b] * slice_total[slice_at(g, wo.c[a], wi.c[b], em)];
  return v;
}

double SpatialStack::emission_density(const Cosines& cw, int em, int z, double r_mm) const {
  const int j = leg_rings().ring_of(r_mm);
  return j < 0 ? 0.0 : emission_density_in(cw, em, z, j);
}

double SpatialStack::excitation_density(int g, const Cosines& cw, int z, double r_mm) const {
  const int j = leg_rings().ring_of(r_mm);
  if (j < 0) return 0.0;
  double d = 0;
  for (int a = 0; a < 2; ++a)
    if (cw.w[a] > 0) d += cw.w[a] * ex_dens[ex_at(g, cw.c[a], z) + j];
  return d;
}

double SpatialStack::emission_fluence(const Cosines& cw, int em, int z) const {
  double v = 0;
  for (int a = 0; a < 2; ++a)
    if (cw.w[a] > 0) v += cw.w[a] * prof->leg_fluence[(size_t(cw.c[a]) * n + em) * Z + z];
  return v;
}

double SpatialStack::excitation_fluence(int g, const Cosines& cw, int z) const {
  double v = 0;
  for (int a = 0; a < 2; ++a)
    if (cw.w[a] > 0) v += cw.w[a] * ex_fluence[(size_t(g) * C + cw.c[a]) * Z + z];
  return v;
}

std::shared_ptr<const SpatialStack> build_spatial_stack(const StackTables& st, std::shared_ptr<const StackProfiles> prof,
                                                        const std::vector<std::vector<float>>& light_shapes) {
  if (!prof) return nullptr;
  auto s = std::make_shared<SpatialStack>();
  s->prof = prof;
  s->n = prof->n;
  s->C = int(prof->cosines.size());
  s->Z = prof->slices();
  std::vector<std::vector<float>> shapes = light_shapes;
  if (shapes.empty()) shapes.assign(1, std::vector<float>(s->n, 1.0f));
  s->G = int(shapes.size());
  // The search radius: where every profile (elastic and legs) holds 99.9 % of its mass.
  const int RE = prof->elastic_rings.rings, RL = prof->leg_rings.rings;
  const size_t n_el = size_t(s->C) * s->n, n_leg = n_el * s->Z;
  const int keep_el = search_rings(prof->elastic_cdf, n_el, RE), keep_leg = search_rings(prof->leg_cdf, n_leg, RL);
  s->search_mm = std::max(prof->elastic_rings.edge(keep_el), prof->leg_rings.edge(keep_leg));
  cut_profiles(prof->elastic_mass, n_el, RE, prof->elastic_rings.ring_of(s->search_mm * (1 - 1e-12)) + 1, s->el_mass, s->el_cdf);
  cut_profiles(prof->leg_mass, n_leg, RL, prof->leg_rings.ring_of(s->search_mm * (1 - 1e-12)) + 1, s->leg_mass, s->leg_cdf);
  fill_slice_weights(st, shapes, *s);
  fill_excitation_legs(st, shapes, *s);
  densities(s->el_mass, prof->elastic_rings, s->el_dens);
  densities(s->leg_mass, prof->leg_rings, s->leg_dens);
  densities(s->ex_mass, prof->leg_rings, s->ex_dens);
  return s;
}

}  // namespace ofl
