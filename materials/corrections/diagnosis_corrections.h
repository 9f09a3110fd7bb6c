// Closing the loop: turn the causes a diagnosis accepted into parameters a
// tissue material can use. Only tissue causes become material parameters: blood absorption (a
// Beer-Lambert layer of oxy/deoxy hemoglobin), extra fluorophores (with their mean share of the
// signal) and emission broadening. Instrument causes (wavelength shift, bandwidth, stray light,
// long-pass leak/edge) and camera causes are returned by name so the caller can route them to
// the instrument or camera model instead.
//
// Used by the tissue material's "diagnosis" option (materials/tissue.cpp):
//   TissueCorrections c = tissue_corrections_from_report(json_of("oralfluor diagnose --json"));
//   GridEem eem_k = apply_tissue_corrections(load_fluorophore(name_k, grid), c);  // per fluorophore
//   and the blood layer as the material's layer_in / layer_out transmittances.
// render_loop.h renders such a material and compares it with the measured spectra.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/chromophores/hemoglobin.h"

namespace ofl {

struct ExtraFluorophoreShare {
  std::string name;          // library name
  double mean_fraction = 0;  // of the measured signal, averaged over the spectra
  double uncertainty = 0;
};

struct TissueCorrections {
  std::optional<BloodAbsorber> blood;   // with excitation_path_factor from the model options
  BloodAbsorber blood_uncertainty;      // one standard uncertainty of oxy/deoxy
  std::vector<ExtraFluorophoreShare> extra_fluorophores;
  double emission_broadening_fwhm_nm = 0;
  std::vector<std::string> instrument_causes;  // accepted causes that are not tissue properties
  std::vector<std::string> unrendered_tissue_causes;  // tissue causes the material cannot express
  bool empty() const { return !blood && extra_fluorophores.empty() && emission_broadening_fwhm_nm <= 0; }
};

// Reads the JSON report of `oralfluor diagnose` (its "causes" array and "model_options").
// Throws InputError when a cause it knows lacks a parameter.
TissueCorrections tissue_corrections_from_report(const nlohmann::json& report);

// Bin-mean decadic optical density of the blood layer on a grid (a tissue material's blood OD).
std::vector<double> blood_optical_density_on_grid(const BloodAbsorber& b, const WavelengthGrid& grid);

// An EEM with the tissue corrections applied: emission broadened by a Gaussian of the given FWHM
// (each excitation column blurred as the diagnosis blurs an emission column, in energy units;
// what the blur moves to or below the excitation wavelength is dropped, so the EEM above the
// diagonal is the fitted model's and the photon albedo can only decrease), then the blood layer
// (apply_blood_to_eem).
GridEem apply_tissue_corrections(const GridEem& eem, const TissueCorrections& c);

}  // namespace ofl
