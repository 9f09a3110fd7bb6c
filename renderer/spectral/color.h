// CIE 1931 colour matching and sRGB encoding, for preview images and for plots.
// The CMF table (assets/spectra/cie/cie1931_xyz_2deg.csv, 370-730 nm, from ISETCam) is read once.
#pragma once
#include <array>
#include <vector>

#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct ColorMatching {
  std::vector<double> x, y, z;  // bin means on a grid
};

// CMFs as bin means over the bins of `grid`.
ColorMatching cie1931_on_grid(const WavelengthGrid& grid);
// CMFs averaged over arbitrary bands [lo_i, hi_i].
ColorMatching cie1931_on_bands(const std::vector<double>& lo_nm, const std::vector<double>& hi_nm);

std::array<double, 3> xyz_to_linear_srgb(const std::array<double, 3>& xyz);
double srgb_encode(double linear);  // IEC 61966-2-1 transfer curve, input clamped to [0, 1]

}  // namespace ofl
