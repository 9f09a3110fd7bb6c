// A synthetic spectral radiance image for testing and documenting the camera and the chromaticity
// analysis without a render: square patches of tongue tissue, one row per fluorophore and one
// column per concentration, lit by an LED whose irradiance falls off smoothly toward the image
// corners (non-uniform light, the condition chromaticity is meant to tolerate). Each patch has
// exactly the radiance the chromaticity reference lines assume,
//   L(lambda) = s(x, y) [ R(lambda) E(lambda) + c (hc / lambda) sum_ex Phi(lambda, ex) E_q(ex) d_ex ] / pi,
// computed on a fine transport grid and averaged into the output bands. The header carries
// oralfluor.vfov_deg, oralfluor.scene and oralfluor.excitation_spd like a rendered image.
#pragma once
#include <string>
#include <vector>

#include "renderer/image/spectral_image.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct ChartOptions {
  std::vector<std::string> fluorophores = {"FAD", "protoporphyrin"};  // one row each (library names)
  std::vector<double> concentrations = {0.0, 1e-4, 1e-3, 1e-2};      // one column each
  int patch_px = 32;                 // patch size in pixels
  Spectrum led = constant_spectrum(0.0);  // LED relative energy SPD (shape only)
  double peak_irradiance = 1.0;      // E at the LED peak at the brightest point, W m^-2 nm^-1
  Spectrum reflectance = constant_spectrum(0.2);
  double shading_corner = 0.5;       // irradiance factor at the image corners (1 at the centre)
  std::vector<double> band_nm;       // output band centres (empty: 400-700 nm every 10 nm)
  double transport_step_nm = 1.0;
  double vfov_deg = 40.0;
};

SpectralImage make_fluorescence_chart(const ChartOptions& opt);

// The shipped example LED (assets/spectra/lights/oraleye_405nm_flood.csv) and tongue reflectance
// (assets/spectra/tissue/tongue_reflectance.csv).
Spectrum example_led_spectrum();
Spectrum tongue_reflectance_spectrum();

}  // namespace ofl
