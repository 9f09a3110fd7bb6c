// How much of a spectrum a set of output bands holds: light (or sensitivity) outside the bands of an
// image is light the camera never sees, so every stage that narrows the spectrum says how much it drops.
#pragma once

#include <string>
#include <vector>

#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct BandCoverage {
  double total = 0;          // integral of the spectrum over the grid
  double outside_share = 0;  // fraction of it outside every band (0 when total is 0)
  double outside_lo_nm = 0, outside_hi_nm = 0;  // range of grid bins with light outside the bands
};

// `values` sampled on `grid` (each sample stands for its bin); bands are [band_lo[b], band_hi[b]].
// A bin partly inside a band counts in proportion to its overlap.
BandCoverage band_coverage(const WavelengthGrid& grid, const std::vector<double>& values,
                           const std::vector<double>& band_lo, const std::vector<double>& band_hi);

// "12.3 % of the LED light (365-395 nm) lies outside the bands 400-700 nm", or "" when the share is
// at most `tolerance`. `what` names the light ("the LED light").
std::string coverage_warning(const BandCoverage& c, const std::string& what, double bands_lo_nm, double bands_hi_nm,
                             double tolerance = 0.01);

}  // namespace ofl
