// Optical filters: measured transmittance tables or parametric long-, short- and band-pass
// edges with a finite slope and an out-of-band optical density. Interference filters move their
// spectrum toward the blue with angle of incidence:
//   lambda(theta) = lambda0 * sqrt(1 - (sin(theta) / n_eff)^2)
// (thin-film approximation; see e.g. Macleod, Thin-Film Optical Filters, ch. 8). Used by LEDs
// (excitation short-pass) and by the camera's filter stack (emission long-pass, NIR cut).
#pragma once
#include <string>

#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {

struct OpticalFilter {
  enum class Kind { kLongpass, kShortpass, kBandpass, kMeasured };
  Kind kind = Kind::kLongpass;
  double edge_nm = 475;       // 50 % point (long/short-pass) or lower edge (band-pass)
  double edge2_nm = 0;        // upper edge (band-pass)
  double width_nm = 5;        // 10 %-90 % transition width
  double od = 4;              // out-of-band optical density: blocking transmittance 10^-od
  double peak = 0.95;         // in-band transmittance
  bool interference = true;   // shifts with angle of incidence
  double n_eff = 2.0;         // effective index of the coating stack
  Spectrum measured;          // for kMeasured
  std::string name;

  // Transmittance at `nm` for light arriving at `aoi_rad` from the filter normal.
  double transmittance(double nm, double aoi_rad = 0.0) const;
  // Factor by which the spectrum moves at this angle (1 at normal incidence).
  double shift_factor(double aoi_rad) const;
  // The filter at a fixed angle as a Spectrum.
  Spectrum at_angle(double aoi_rad = 0.0) const;
};

}  // namespace ofl
