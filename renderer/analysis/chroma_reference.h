// Reference lines for the chromaticity plot, the construction of figure 5 of the reference paper
// (Farrell et al., OralEye): what chromaticity this camera would record from tongue tissue whose
// reflectance R is mixed with an increasing concentration c of one fluorophore, under the scene's
// LED. In photon units, as the renderer computes fluorescence (quantum yields hold),
//   L_q(lambda) = [ R(lambda) E_q(lambda) + c sum_ex Phi(lambda, ex) E_q(ex) d_ex ] / pi,
//   E_q = E lambda / (h c)   (E the LED's energy spectrum; its absolute scale cancels),
//   S_k = sum_lambda L_q(lambda) QE_sys,k(lambda) d_lambda,  (r, g) = (S_R, S_G) / (S_R + S_G + S_B),
// QE_sys,k = lens T x filter stack (at the ROI's field angle) x QE_k, restricted to the wavelengths
// the radiance image covered (so the lines match what the camera simulation could see).
// c is the fluorophore's photon albedo at its excitation peak (library EEMs are normalised to 1);
// each line starts at c = 0, the tongue-reflectance point.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/camera_description.h"
#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct ReferenceSetup {
  WavelengthGrid grid;
  std::vector<double> excitation_q;  // E_q on the grid (relative photon irradiance)
  std::vector<double> reflectance;   // R on the grid
  std::array<std::vector<double>, 3> response;  // QE_sys,k on the grid, zero outside the camera range
};

struct ReferenceOptions {
  double step_nm = 1.0;
  double camera_lo_nm = 0, camera_hi_nm = 0;  // wavelengths the camera saw (the EXR's bands); 0: all
  double aoi_front_rad = 0, aoi_sensor_rad = 0;
};

// The grid spans the LED spectrum and the camera range.
ReferenceSetup make_reference_setup(const CameraDescription& cam, const Spectrum& led_energy,
                                    const Spectrum& reflectance, const ReferenceOptions& opt);

// Channel signals S_R, S_G, S_B (relative) for reflectance plus c times `eem` (eem may be null: c ignored).
std::array<double, 3> reference_signal(const ReferenceSetup& s, const GridEem* eem, double c);
std::array<double, 2> reference_rg(const ReferenceSetup& s, const GridEem* eem, double c);

struct ReferenceLine {
  std::string fluorophore;
  std::vector<double> concentration;           // starts with 0
  std::vector<std::array<double, 2>> rg;       // rg[0] is the tongue-reflectance point
  std::array<double, 2> pure_rg = {0, 0};      // the fluorophore alone (the limit of large c)
  double balance_concentration = 0;            // c at which fluorescence and reflection give equal signal
  bool visible = true;                         // false when this camera cannot see the fluorescence
  nlohmann::json to_json() const;
};

// `concentrations` empty: 0 and 17 values from balance/100 to 100 x balance (log spaced), so that
// every line runs from the tongue point to near the pure fluorophore whatever its brightness.
ReferenceLine reference_line(const ReferenceSetup& s, const std::string& name, const GridEem& eem,
                             const std::vector<double>& concentrations = {});

}  // namespace ofl
