// Excitation-emission matrices (Donaldson matrices) of fluorophores.
// Phi(em, ex): photons emitted per nm of emission wavelength per photon of excitation light at
// ex falling on the surface (absorption and quantum yield folded in). Files follow the shared
// convention: rows emission, columns excitation. On the transport grid an EEM is kept zero on
// and below the diagonal (Stokes: no emission at or below the excitation wavelength).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

// An EEM on its own axes, as read from a file.
struct Eem {
  std::vector<double> em_nm, ex_nm;
  std::vector<double> values;  // row-major [em][ex]
  double at(size_t em, size_t ex) const { return values[em * ex_nm.size() + ex]; }
};

// An EEM on the transport grid: N x N, row = emission index, column = excitation index.
struct GridEem {
  WavelengthGrid grid;
  std::vector<double> m;  // [em * N + ex], zero for em <= ex
  std::string source;     // the file it was read from (for error messages), empty if built in code
  int n() const { return grid.size(); }
  double at(int em, int ex) const { return m[static_cast<size_t>(em) * n() + ex]; }
  double& at(int em, int ex) { return m[static_cast<size_t>(em) * n() + ex]; }
  // Photon albedo of the fluorescence at excitation index ex: sum over em of Phi * step.
  std::vector<double> photon_albedo() const;
  // Emission (per nm, photon units) under an excitation spectrum e(ex) in photon units:
  // out(em) = sum_ex Phi(em, ex) e(ex) step.
  std::vector<double> apply(const std::vector<double>& excitation) const;
  void scale(double s) { for (double& v : m) v *= s; }
};

// Reads a matrix CSV (first header cell "emission_nm\excitation_nm", then excitation nm; each
// row starts with its emission nm). NaN, negative entries and non-increasing axes are input
// errors naming file and line.
Eem read_eem_csv(const std::filesystem::path& file);

// An EEM from separate excitation and emission spectra (Kasha's rule: the emission shape does not
// depend on the excitation wavelength): Phi(em, ex) = x(ex) * e(em) / integral(e), before the
// Stokes mask. With x peak-normalised, the photon albedo at the excitation peak is 1 when no
// emission lies below the peak.
GridEem eem_from_pair(const Spectrum& excitation, const Spectrum& emission, const WavelengthGrid& grid);

// Bin-averages both axes onto the grid (zero outside the file's range) and applies the Stokes mask.
GridEem resample(const Eem& eem, const WavelengthGrid& grid);

// Peak excitation and emission wavelengths of a grid EEM (argmax of photon albedo, and argmax of
// the emission under excitation at that peak).
struct EemPeaks {
  double excitation_nm = 0, emission_nm = 0, max_albedo = 0;
};
EemPeaks find_peaks(const GridEem& eem);

}  // namespace ofl
