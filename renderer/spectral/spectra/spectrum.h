// Spectra independent of any grid, and their tabulation on a WavelengthGrid.
// A Spectrum is a function of wavelength (piecewise linear table, analytic shape, filter, or a
// product of those) plus the wavelengths where it has kinks, so that tabulating it as bin
// averages is exact for tables and accurate for smooth shapes. Bin averages (not point samples)
// keep the area of narrow LED lines when a 2 nm measurement is put on a 5 nm grid.
#pragma once
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "renderer/core/files/csv.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

// What a table is outside its wavelength range.
enum class Outside { kZero, kClamp };

// Piecewise-linear table; wavelengths strictly increasing, at least two samples.
struct TabulatedSpectrum {
  std::vector<double> nm;
  std::vector<double> value;
  Outside outside = Outside::kZero;
  double eval(double wl) const;
};

struct Spectrum {
  std::function<double(double)> eval;   // value at a wavelength in nm
  std::vector<double> kinks;            // wavelengths where eval is not smooth (sorted)
  std::string description;              // for logs and error messages

  double operator()(double nm) const { return eval(nm); }
};

Spectrum constant_spectrum(double v);
Spectrum table_spectrum(TabulatedSpectrum t, std::string description);
// Peak value 1 at `peak_nm`, full width at half maximum `fwhm_nm`.
Spectrum gaussian_spectrum(double peak_nm, double fwhm_nm);
// Planck's law, normalised to 1 at its peak (relative SPD of a blackbody at `kelvin`).
Spectrum blackbody_spectrum(double kelvin);
Spectrum product_spectrum(const std::vector<Spectrum>& factors);
Spectrum sum_spectrum(const std::vector<Spectrum>& terms);
Spectrum scaled_spectrum(Spectrum s, double factor);

// Planck spectral radiance in W sr^-1 m^-2 nm^-1 (absolute).
double planck_radiance(double nm, double kelvin);

// Mean of `s` over each bin of `grid`.
std::vector<double> tabulate(const Spectrum& s, const WavelengthGrid& grid);
// Mean of `s` over [a, b] (exact for piecewise-linear tables).
double average(const Spectrum& s, double a_nm, double b_nm);

// Reads a spectrum CSV in the shared-data convention (first column wavelength in nm).
// `column` empty means the only value column. Rejects non-increasing wavelengths and NaN with
// file and line; rejects negative values unless `allow_negative` or `clip_negative`.
struct SpectrumCsvOptions {
  std::string column;
  double scale = 1.0;
  bool allow_negative = false;
  bool clip_negative = false;
  Outside outside = Outside::kZero;
};
// An ISETCam-style .mat (variables `wavelength` and `data`, see renderer/formats/mat_spectrum.h) is
// accepted wherever a spectrum CSV is, the file name's .mat extension deciding.
TabulatedSpectrum read_spectrum_csv(const std::filesystem::path& file, const SpectrumCsvOptions& opt = {});
// The table behind a spectrum file: wavelength column then named value columns, from a CSV or a .mat.
CsvNumeric read_spectrum_table(const std::filesystem::path& file);

// Integral over the grid (sum times step).
double integrate(const std::vector<double>& values, const WavelengthGrid& grid);

}  // namespace ofl
