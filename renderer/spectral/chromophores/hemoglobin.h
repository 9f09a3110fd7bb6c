// Blood as a Beer-Lambert absorber made of oxy- and deoxy-hemoglobin (Prahl's decadic molar
// extinction coefficients, assets/spectra/hemoglobin). Tissue fluorescence generated under a
// vascularised layer reaches the surface attenuated by 10^-OD(em); the excitation light going in
// is attenuated by 10^-OD(ex) along its own path. Used by `diagnose` (the blood_absorption cause)
// and meant for tissue materials: the functions at the end turn a fitted absorber into modified
// EEMs and reflectances on the transport grid.
#pragma once
#include <vector>

#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

// Prahl's tables: molar extinction in cm^-1 / (mol/L), base 10, per mole of hemoglobin tetramer.
struct HemoglobinTables {
  TabulatedSpectrum oxy, deoxy;
};
// Loaded once from assets/spectra/hemoglobin (thread safe).
const HemoglobinTables& hemoglobin_tables();

// A blood layer described by the product of hemoglobin concentration and path length, because
// that product is all Beer-Lambert can see: OD(lambda) = (eps_oxy * oxy + eps_deoxy * deoxy) * 1e-6
// with oxy/deoxy in micromol/L * cm.
struct BloodAbsorber {
  double oxy_uM_cm = 0;    // oxy-hemoglobin concentration x path length (umol/L x cm)
  double deoxy_uM_cm = 0;  // deoxy-hemoglobin concentration x path length (umol/L x cm)
  // Excitation light crosses the layer too; its path is this many times the emission path
  // (0 = the excitation is not attenuated).
  double excitation_path_factor = 0;

  double total_uM_cm() const { return oxy_uM_cm + deoxy_uM_cm; }
  double saturation() const { return total_uM_cm() > 0 ? oxy_uM_cm / total_uM_cm() : 0; }
  // A layer of whole blood: thickness in micrometres, hemoglobin in g/L (150 typical), oxygen
  // saturation 0..1, blood volume fraction 0..1 of the layer.
  static BloodAbsorber whole_blood(double thickness_um, double saturation, double volume_fraction = 1.0,
                                   double hemoglobin_g_per_L = 150.0);
};

// Decadic optical density at one wavelength, and as a Spectrum (kinks at the table samples).
double blood_optical_density(const BloodAbsorber& b, double nm);
Spectrum blood_optical_density_spectrum(const BloodAbsorber& b);
// Transmittance 10^-OD: point values, and bin means on a grid (mean of 10^-OD over each bin,
// which keeps narrow bands right on a coarse grid).
double blood_transmittance(const BloodAbsorber& b, double nm);
std::vector<double> blood_transmittance(const BloodAbsorber& b, const WavelengthGrid& grid);

// For materials: the fluorescence of a tissue under a blood layer, as an EEM,
//   Phi'(em, ex) = T(em) * Phi(em, ex) * T(ex)^excitation_path_factor,
// and a diffuse reflectance seen through the layer twice (in and out): R'(l) = R(l) * T(l)^2.
GridEem apply_blood_to_eem(const GridEem& eem, const BloodAbsorber& b);
std::vector<double> apply_blood_to_reflectance(const std::vector<double>& reflectance, const WavelengthGrid& grid,
                                               const BloodAbsorber& b);

// Blood as a volume absorber (layered tissue): the absorption coefficient of whole blood in 1/mm,
//   mua_blood(lambda) = ln(10) * [S eps_oxy + (1 - S) eps_deoxy] * (Hb / 64500 g/mol) / 10,
// with Prahl's decadic molar extinction (cm^-1 M^-1), Hb in g/L, S the oxygen saturation.
double whole_blood_mua_per_mm(double nm, double saturation, double hemoglobin_g_per_L = 150.0);
// mua of a tissue holding blood at `volume_fraction`, in 1/mm. With vessel_radius_um > 0 the blood
// sits in vessels of that radius instead of being spread evenly, and its absorption is reduced by
// the pigment-packaging factor C = (1 - exp(-2 mua_bl R)) / (2 mua_bl R) (Svaasand et al. 1995;
// van Veen et al., J Biomed Opt 2005), which matters in the Soret band where mua_bl R >> 1.
Spectrum tissue_blood_mua_spectrum(double volume_fraction, double saturation, double hemoglobin_g_per_L = 150.0,
                                   double vessel_radius_um = 0.0);

}  // namespace ofl
