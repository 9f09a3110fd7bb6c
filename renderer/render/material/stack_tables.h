// What the layered-tissue random walk looks up per wavelength lane, prepared once per render in
// float: per layer the depth of its faces, index, HG anisotropy, chromophore absorption and
// scattering, and per fluorophore its absorption shape and re-emission matrix (with row sums and
// CDFs for sampling an excitation wavelength, as the surface albedo matrix has). Units: mm, 1/mm.
#pragma once
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "materials/interfaces/dielectric_interface.h"
#include "materials/description/layered.h"
#include "renderer/spectral/chromophores/eem.h"

namespace ofl {

struct StackResponse;  // renderer/render/stack/stack_response_table.h
struct SpatialStack;   // renderer/render/spatial/spatial_tables.h

struct StackFluorophoreTables {
  std::vector<float> absorb;   // [ex] mua_f(ex), 1/mm
  std::vector<float> emit;     // [em * n + ex] sigma_f(em <- ex) * dlambda, 1/mm (empty: no re-emission)
  std::vector<float> row_sum;  // [em] kappa(em) = sum over ex of emit, 1/mm
  std::vector<float> row_cdf;  // [em * n + ex] normalised running sum over ex
  int texture = -1;
  float texture_offset = 0, texture_scale = 1;
};

struct StackLayerTables {
  double top = 0, bottom = 0;  // depth of the faces in mm (bottom = +inf for a semi-infinite layer)
  double ior = 1;
  double g = 0;
  bool clear = true;           // nothing absorbs or scatters: light crosses it unchanged
  std::vector<float> mua, mus; // [lambda] 1/mm, chromophores only (fluorophores are added per point)
  std::vector<StackFluorophoreTables> fluors;
};

struct StackTables {
  bool enabled = false;
  double ambient_ior = 1;
  DielectricInterface top;             // ambient | layer 0
  GgxCoating top_lobe;                 // the same interface's reflection lobe, with its albedo table (rough only)
  std::vector<StackLayerTables> layers;
  StackBottom bottom = StackBottom::kSemiInfinite;
  double below_ior = 1;
  // Per LED spectrum group, the grid bins where it emits and its photon shape there: direct
  // excitation inside the stack is summed over these.
  std::vector<std::vector<std::pair<int, float>>> led_support;
  // Per LED spectrum group and layer, the diffusion attenuation sqrt(3 mua (mua + mus (1 - g))) of
  // its light (1/mm, photon-shape weighted): how fast scattered excitation fades with depth, which
  // sets how often next-event estimation samples it (layered_bsdf.cpp).
  std::vector<std::vector<float>> led_mu_eff;
  // The tabulated response (transport "table"), or null: the walk runs at every vertex.
  std::shared_ptr<const StackResponse> response;
  // The lateral profiles (transport "spatial"), with the table above for the directional part; null
  // otherwise.
  std::shared_ptr<const SpatialStack> spatial;
  // Transport "volume": the walk runs at every vertex with its lateral position tracked and crosses
  // into the material under it (renderer/render/integrator/layered_bsdf.h).
  bool volume = false;
  bool fluorescent() const {
    for (auto& l : layers)
      if (!l.fluors.empty()) return true;
    return false;
  }
};

// A re-emission matrix m[em * n + ex] = value(em, ex) for ex < em (Stokes), with each row's sum and
// its normalised running sum over ex (the CDF a lane's excitation bin is drawn from; 1 where a row
// is empty). Shared by surface fluorophores and layer fluorophores.
template <class Value>
void tabulate_reemission(int n, Value value, std::vector<float>& m, std::vector<float>& row_sum, std::vector<float>& row_cdf) {
  m.assign(size_t(n) * n, 0.0f);
  row_sum.assign(n, 0.0f);
  row_cdf.assign(size_t(n) * n, 1.0f);
  for (int em = 0; em < n; ++em) {
    double acc = 0;
    for (int ex = 0; ex < em; ++ex) {
      double v = value(em, ex);
      m[size_t(em) * n + ex] = float(v);
      acc += v;
      row_cdf[size_t(em) * n + ex] = float(acc);
    }
    row_sum[em] = float(acc);
    for (int ex = 0; ex < em; ++ex) {
      float& c = row_cdf[size_t(em) * n + ex];
      c = acc > 0 ? float(c / acc) : 1.0f;
    }
  }
}

// Tabulates a layer stack; `light_shapes` are the renderer's LED photon shapes per group.
// With fluorescence off the fluorophores still absorb but do not re-emit.
StackTables build_stack_tables(const LayerStack& stack, const std::vector<GridEem>& eems,
                               const std::vector<std::vector<float>>& light_shapes, bool fluorescence);

}  // namespace ofl
