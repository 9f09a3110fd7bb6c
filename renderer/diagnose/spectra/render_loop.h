// Closing the loop: the causes a diagnosis accepted become tissue material
// options, a flat patch of that material is rendered under the measured LED spectrum of a
// diagnosed spectrum, and the rendered radiance goes through the diagnosis' own instrument model
// (long-pass, leak, the accepted instrument causes such as bandwidth) so that it is compared with
// the measured spectrum exactly as the diagnosis compares its prediction. Only the material comes
// from the renderer; everything the spectroradiometer adds is the diagnosis'.
//
// How fitted amplitudes become concentrations: the diagnosis' columns are the emission of a
// library fluorophore at unit concentration under the light's measured radiance (W sr^-1 m^-2
// nm^-1 from a white target), and its amplitudes multiply the spectrum divided by its mean, so a
// concentration is amplitude x mean radiance. The patch's LED is scaled so that a white Lambertian
// patch would show that radiance, which keeps fluorescence and reflected light in their measured
// proportion. Per spectrum (`item_concentrations`, the diagnosis' own local fit) or one set for
// many spectra (`joint_concentrations`, each spectrum with its own scale and leak amplitude).
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/diagnose/problem/diagnose_problem.h"
#include "renderer/diagnose/spectra/flat_patch.h"
#include "renderer/diagnose/spectra/forward_model.h"

namespace ofl {

// Renders the flat patch of `material` under item `item`'s light of `p`: the image-mean radiance (or
// its fluorescence, `fluorescence_only`) on the model's grid (zero outside the bands).
std::vector<double> render_item_patch(const SpectraProblem& p, int item, const nlohmann::json& material,
                                      const PatchRenderOptions& o = {});

// The rendered radiance against item `item`'s measured spectrum: y / mean = s * instrument(radiance)
// + leak amplitudes, s and amplitudes >= 0 (NNLS, as the diagnosis fits its amplitudes), with the
// instrument of `instrument_state` (its tissue causes are ignored). locals["scale"] = s.
ItemFit compare_rendered(const SpectraProblem& p, const ModelState& instrument_state, int item,
                         const std::vector<double>& radiance);

// `s` without its tissue causes (blood, broadening, extra fluorophores): the instrument alone.
ModelState instrument_only(const SpectraProblem& p, const ModelState& s);

// Concentrations (library fluorophore -> photon albedo at its excitation peak) of the tissue
// columns of `state` fitted to item `item` alone: the diagnosis' own NNLS amplitudes x the
// spectrum's mean radiance.
std::map<std::string, double> item_concentrations(const SpectraProblem& p, const ModelState& state, int item);

// One set of concentrations for all `items` under `state`: y_i / mean_i = s_i (T_i c) + B_i a_i
// with c, s_i, a_i >= 0 (T_i the tissue columns, B_i the leak columns), by alternating NNLS from
// the mean of the per-item fits; c scaled so that the median of s_i mean_i is 1 (absolute units
// when the measurements and the light spectra share a calibration).
std::map<std::string, double> joint_concentrations(const SpectraProblem& p, const ModelState& state,
                                                   const std::vector<int>& items, int iterations = 60);

// The causes of `state` as the JSON a tissue material's "diagnosis" option reads (the "causes"
// and "model_options" of an `oralfluor diagnose` report), with extra fluorophores' mean shares
// over `items` under `state`.
nlohmann::json state_report(const SpectraProblem& p, const ModelState& state, const std::vector<int>& items);

// {"type": "tissue", "preset": preset, "coating": false, "concentrations": {...}} with every
// fluorophore of the preset that `concentrations` does not name set to 0, plus
// "diagnosis": report_file when not empty (its tissue causes join the material).
nlohmann::json tissue_material(const std::string& preset, const std::map<std::string, double>& concentrations,
                               const std::string& report_file = "");

// The material a fitted state renders back as for item `item`: when the state holds the
// layered_tissue cause and the item's site has a stack, that stack with the fitted thickness and
// blood and the amounts `concentrations` (for the fluorophores it holds: multiples of the preset's;
// fluorophores it does not hold are not rendered); otherwise tissue_material(preset, ...).
nlohmann::json fitted_material(const SpectraProblem& p, const ModelState& state, int item, const std::string& preset,
                               const std::map<std::string, double>& concentrations, const std::string& report_file = "");

// The diagnosis' own prediction for item `item` under `state` with fixed amounts (by column name,
// absolute, as item_concentrations gives them; columns not named count 0), before the instrument's
// free amplitudes: what a render of the same material should equal.
Eigen::VectorXd modelled_spectrum(const SpectraProblem& p, const ModelState& state, int item,
                                  const std::map<std::string, double>& amounts);

// Measurements made by the renderer (tests with a known tissue): for every item of `tmpl` (whose
// spectra `set` holds, in the same order), the flat patch of material(item) rendered with seed
// `gen.seed + item`, through the instrument of `instrument`, sampled at the item's wavelengths,
// plus shot-like noise of relative size `noise` (sigma = noise sqrt(v mean)) from `rng_seed`.
// Throws std::runtime_error when a render is dark.
void render_measurements(const SpectraProblem& tmpl, SpectraSet& set, const std::function<nlohmann::json(int)>& material,
                         const ModelState& instrument, const PatchRenderOptions& gen, double noise, uint64_t rng_seed);

// Pooled RMSE of residuals: sqrt(sum r^2 / number of residuals).
double pooled_rmse(const std::vector<ItemFit>& fits, const std::vector<int>& items);

}  // namespace ofl
