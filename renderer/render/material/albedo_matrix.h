// The albedo matrix of a surface point seen by one wavelength lane: A = diag(R) + sum_j c_j Phi_j
// dlambda, with concentrations after texture lookup. A lane at emission wavelength em either
// reflects (stays at em) or is re-radiated from an excitation wavelength sampled in proportion to
// sum_j c_j Phi_j(em, .); either way its weight is the row sum R(em) + F(em).
#pragma once
#include <algorithm>

#include "materials/description/material.h"
#include "renderer/render/material/material_tables.h"
#include "renderer/render/trace/rng.h"

namespace ofl {

struct LocalMaterial {
  const MaterialTables* m = nullptr;
  float rscale = 1;  // reflectance texture factor
  int nf = 0;        // fluorophores in use
  float conc[kMaxFluorophoresPerMaterial] = {};
};

// Total fluorescent in-scatter F(em) = sum_j c_j F_j(em).
inline float fluor_total(const LocalMaterial& lm, int em) {
  float s = 0;
  for (int j = 0; j < lm.nf; ++j) s += lm.conc[j] * lm.m->fluorophores[j].row_sum[em];
  return s;
}

// Samples an excitation index for emission index em with probability
// sum_j c_j phi_j(em, ex) / F(em); `total` is F(em), u uniform in [0, 1).
inline int sample_excitation(const LocalMaterial& lm, int em, float total, float u, int n) {
  float target = u * total;
  int j = 0;
  for (; j < lm.nf - 1; ++j) {
    float w = lm.conc[j] * lm.m->fluorophores[j].row_sum[em];
    if (target < w) break;
    target -= w;
  }
  const FluorophoreTables& f = lm.m->fluorophores[j];
  float w = lm.conc[j] * f.row_sum[em];
  float uu = w > 0 ? std::clamp(target / w, 0.0f, 0.99999994f) : u;
  const float* cdf = f.row_cdf.data() + size_t(em) * n;
  int ex = int(std::upper_bound(cdf, cdf + em, uu) - cdf);
  return std::min(ex, std::max(em - 1, 0));
}

// One albedo-matrix step for a lane at `wl`: reflect (stay) or re-radiate (move to an excitation
// wavelength); returns the weight R + F and sets *reradiated when the lane was re-radiated.
inline float albedo_step(const LocalMaterial& lm, int& wl, Rng& rng, int n, bool* reradiated = nullptr) {
  float r = lm.m->reflectance[wl] * lm.rscale;
  float f = lm.nf ? fluor_total(lm, wl) : 0.0f;
  float tot = r + f;
  if (f > 0 && rng.next_float() * tot >= r) {
    wl = sample_excitation(lm, wl, f, rng.next_float(), n);
    if (reradiated) *reradiated = true;
  }
  return tot;
}

}  // namespace ofl
