#include "renderer/render/material/stack_tables.h"

#include <algorithm>
#include <cmath>

namespace ofl {

namespace {

// mua_f(ex) = mua_peak a(ex) / a_peak and sigma_f(em <- ex) = mua_peak QY Phi(em, ex) / a_peak
// (materials/description/layered.h).
StackFluorophoreTables fluorophore_tables(const LayerFluorophore& f, const GridEem& eem, bool emit) {
  const int n = eem.n();
  const double step = eem.grid.step_nm;
  auto albedo = eem.photon_albedo();
  double peak = *std::max_element(albedo.begin(), albedo.end());
  StackFluorophoreTables t;
  t.texture = f.texture;
  t.texture_offset = float(f.texture_offset);
  t.texture_scale = float(f.texture_scale);
  t.absorb.resize(n);
  for (int i = 0; i < n; ++i) t.absorb[i] = float(f.mua_peak_per_mm * albedo[i] / peak);
  t.row_sum.assign(n, 0.0f);
  if (!emit) return t;  // absorbs, never re-emits: emit and row_cdf stay empty
  const double k = f.mua_peak_per_mm * f.quantum_yield / peak;
  tabulate_reemission(n, [&](int em, int ex) { return k * eem.at(em, ex) * step; }, t.emit, t.row_sum, t.row_cdf);
  return t;
}

}  // namespace

StackTables build_stack_tables(const LayerStack& stack, const std::vector<GridEem>& eems,
                               const std::vector<std::vector<float>>& light_shapes, bool fluorescence) {
  StackTables t;
  if (!stack.enabled) return t;
  t.enabled = true;
  t.volume = stack.transport == StackTransport::kVolume;
  t.ambient_ior = stack.ambient_ior;
  t.top = DielectricInterface(stack.top_roughness, stack.ambient_ior, stack.layers.front().ior);
  if (stack.top_roughness > 0) t.top_lobe.prepare(stack.layers.front().ior / stack.ambient_ior, stack.top_roughness);
  t.bottom = stack.bottom;
  t.below_ior = stack.below_ior;
  double depth = 0;
  for (const TissueLayer& l : stack.layers) {
    StackLayerTables lt;
    lt.top = depth;
    lt.bottom = l.semi_infinite() ? std::numeric_limits<double>::infinity() : depth + l.thickness_mm;
    depth = lt.bottom;
    lt.ior = l.ior;
    lt.g = l.g;
    lt.mua.assign(l.mua.begin(), l.mua.end());
    lt.mus.assign(l.mus.begin(), l.mus.end());
    for (const auto& f : l.fluorophores) {
      if (f.mua_peak_per_mm <= 0) continue;
      lt.fluors.push_back(fluorophore_tables(f, eems[f.eem], fluorescence));
    }
    lt.clear = lt.fluors.empty() && std::all_of(l.mua.begin(), l.mua.end(), [](double v) { return v == 0; }) &&
               std::all_of(l.mus.begin(), l.mus.end(), [](double v) { return v == 0; });
    t.layers.push_back(std::move(lt));
  }
  for (const auto& shape : light_shapes) {
    std::vector<std::pair<int, float>> support;
    float peak = shape.empty() ? 0.0f : *std::max_element(shape.begin(), shape.end());
    for (int i = 0; i < int(shape.size()); ++i)
      if (shape[i] > 0 && shape[i] >= 1e-7f * peak) support.emplace_back(i, shape[i]);
    std::vector<float> mu_eff;
    for (const StackLayerTables& L : t.layers) {
      double sum = 0, norm = 0;
      for (const auto& [i, S] : support) {
        double mua = L.mua[i];
        for (const auto& f : L.fluors) mua += f.absorb[i];
        sum += S * std::sqrt(3.0 * mua * (mua + L.mus[i] * (1.0 - L.g)));
        norm += S;
      }
      mu_eff.push_back(norm > 0 ? float(sum / norm) : 0.0f);
    }
    t.led_mu_eff.push_back(std::move(mu_eff));
    t.led_support.push_back(std::move(support));
  }
  return t;
}

}  // namespace ofl
