// The `layered_tissue` cause of a spectra diagnosis (docs/diagnose.md, "Layered tissue"): the
// tissue of one site is a layered_tissue stack (a preset, docs/layered-tissue.md) whose epithelial
// thickness, blood volume fraction and blood oxygen saturation are fitted, one set per site for
// all its excitations; the fluorophores' volume concentrations are the spectra's amplitudes, in
// units of the preset's own concentrations.
//
// What it computes. A fluorophore k spread through the layers that hold it, under light L (radiance
// E_L on a white target, so irradiance pi E_L), viewed along the normal with the light at the
// flat patch's 45 degrees (flat_patch.h), gives the radiance
//   col_k(em) = pi sum_ex f_k(em <- ex) E_L(ex) ex / em,
//   f_k(em <- ex) = 1/(4 pi) sum_l (n_a/n_l)^2 integral_l Phi(z; mu_o, em) sigma_k,l(em <- ex) Phi(z; mu_i, ex) dz
// (the factorisation the layered table uses, renderer/render/stack/stack_response.h), with
// sigma_k,l = mua_k,l QY_k,l Phi_k(em, ex) / a_peak,k (docs/layered-tissue.md). Within an LED band
// the fluence is averaged over the light's absorbed photons, X_k,L(z) = sum_ex w(ex) Phi(z; mu_i, ex)
// / sum w, w = a_k(ex) E_L(ex) ex, so that
//   col_k(em) = surface column_k(em) x F_k,L(em),
//   F_k,L(em) = 1/4 sum_l (mua QY)_k,l / a_peak,k (n_a/n_l)^2 integral_l Phi(z; mu_o, em) X_k,L(z) dz,
// where the surface column is the diagnosis' own (sum_ex Phi_k E ex / em). Exact when the emission
// shape does not change across the LED band (the library EEMs are nearly separable there).
//
// How it is computed. The fluence comes from the stack's own random walk (stack_fluence, the walks
// that fill the render-time table) on a coarse transport grid, at every node of a grid over
// (thickness, blood fraction, saturation); F is stored per node on the coarse grid, interpolated
// multilinearly in log F between nodes and linearly in wavelength. Nodes are computed when first
// needed (thread safe, each node seeded by itself, so results do not depend on threads or order).
#pragma once
#include <array>
#include <map>
#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct LayeredSiteSpec {
  std::string site;           // value of the site column
  nlohmann::json material;    // a layered_tissue material: {"preset": "lateral_tongue", ...overrides}
  std::string source;         // where it was given (for errors)
};

// The model JSON's "layered_tissue" block (docs/diagnose.md).
struct LayeredCauseOptions {
  bool enabled = false;
  std::string site_column = "site";
  std::vector<LayeredSiteSpec> sites;
  std::string epithelium = "epithelium";  // the layer whose thickness is fitted
  double transport_step_nm = 5;           // coarse grid of the walks
  int photons = 3000;                     // walks per cosine and wavelength group, per node
  double view_cos = 1.0, light_cos = 0.70710678118654752;  // flat patch geometry (flat_patch.h)
  std::vector<double> thickness_mm = {0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.65};
  std::vector<double> blood_fraction = {0, 0.005, 0.01, 0.02, 0.04, 0.08, 0.14, 0.2};
  std::vector<double> saturation = {0.3, 0.6, 0.8, 1.0};
  // Wavelengths the walks cover (0: the diagnosis grid's ends); set by the spectra problem to the
  // lights' band and the fit range, outside which the factor is held at its end value.
  double min_nm = 0, max_nm = 0;
};

class LayeredSite {
 public:
  // `eems` and `names`: the diagnosis' fluorophores on its grid; `lights`: each light's excitation
  // radiance on that grid (what the surface columns were made from). Throws InputError naming
  // `spec.source` when the material is not a usable layered_tissue stack.
  LayeredSite(const LayeredSiteSpec& spec, const LayeredCauseOptions& opt, const WavelengthGrid& grid,
              const std::vector<std::string>& names, const std::vector<GridEem>& eems,
              const std::vector<std::vector<double>>& lights);
  ~LayeredSite();

  const std::string& site() const { return spec_.site; }
  // Whether fluorophore k lives in the stack (else its column stays a surface column).
  bool holds(int k) const { return held_[k]; }
  // F_k,L on the diagnosis grid at theta = (thickness mm, blood fraction, saturation).
  std::vector<double> factor(int k, int light, const std::array<double, 3>& theta) const;
  // The material with theta applied (what the renderer renders back); `amounts` (by fluorophore
  // name) multiply the fluorophores' mua_per_mm, e.g. a diagnosis' fitted amounts ("amount:<name>"
  // of its item fits: for the fluorophores the stack holds, multiples of the preset's own).
  nlohmann::json material(const std::array<double, 3>& theta, bool table_transport = true,
                          const std::map<std::string, double>& amounts = {}) const;
  // Names of the layers that hold blood (their fraction and saturation are the fitted ones).
  // Nodes computed so far and the CPU seconds they took.
  int nodes_computed() const { return computed_.load(); }
  double node_seconds() const { return 1e-3 * double(node_ms_.load()); }

 private:
  struct Node;
  const Node& node(int it, int ib, int is) const;
  void compute(Node& n, const std::array<double, 3>& theta) const;

  LayeredSiteSpec spec_;
  LayeredCauseOptions opt_;
  WavelengthGrid grid_;                // the diagnosis grid
  std::vector<std::string> names_;
  std::vector<double> a_peak_;         // per fluorophore: peak photon albedo
  std::vector<std::vector<double>> absorb_;  // per fluorophore: photon albedo a_k(ex) on the grid
  std::vector<std::vector<double>> lights_;
  std::vector<bool> held_;
  std::vector<std::string> blood_layers_;
  std::vector<std::unique_ptr<Node>> nodes_;
  mutable std::atomic<int> computed_{0};
  mutable std::atomic<long long> node_ms_{0};
};

// Parses the model JSON's "layered_tissue" block (errors name the file and the field).
LayeredCauseOptions parse_layered_cause(const JsonNode& n);

}  // namespace ofl
