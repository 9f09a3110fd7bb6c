// Spectral core: grids, tabulation by bin means, analytic spectra, CSV validation.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "renderer/core/errors/error.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectra/units.h"

using namespace ofl;

TEST(Spectrum, GaussianBinMeansKeepArea) {
  // A 10 nm FWHM line on a 5 nm grid: the tabulated integral equals the analytic area
  // sigma * sqrt(2 pi) to 1e-4.
  WavelengthGrid g{350, 830, 5};
  auto v = tabulate(gaussian_spectrum(402.3, 10.0), g);
  double sigma = 10.0 / (2 * std::sqrt(2 * std::log(2.0)));
  EXPECT_NEAR(integrate(v, g), sigma * std::sqrt(2 * kPi), 1e-4 * sigma);
}

TEST(Spectrum, TableBinMeanIsExactForLinear) {
  TabulatedSpectrum t{{400, 500}, {0.0, 1.0}, Outside::kClamp};
  auto s = table_spectrum(t, "ramp");
  WavelengthGrid g{420, 480, 10};
  auto v = tabulate(s, g);
  for (int i = 0; i < g.size(); ++i) EXPECT_NEAR(v[i], (g.wavelength(i) - 400) / 100.0, 1e-12);
}

TEST(Spectrum, TableEndIsAJumpNotARamp) {
  // A table that is zero outside [402, 420] nm: the bin [400, 405] holds 3 nm of value 1 -> 0.6.
  TabulatedSpectrum t{{402, 420}, {1.0, 1.0}, Outside::kZero};
  EXPECT_NEAR(average(table_spectrum(t, "box"), 400, 405), 0.6, 1e-6);
}

TEST(Spectrum, BlackbodyPeakFollowsWien) {
  WavelengthGrid g{300, 1500, 1};
  auto v = tabulate(blackbody_spectrum(5000), g);
  int best = 0;
  for (int i = 0; i < g.size(); ++i) if (v[i] > v[best]) best = i;
  EXPECT_NEAR(g.wavelength(best), 2.897771955e6 / 5000, 1.0);
}

TEST(Spectrum, PhotonEnergy) {
  // 500 nm photon: h c / lambda = 3.9728916e-19 J.
  EXPECT_NEAR(photon_energy_J(500) / 3.9728916e-19, 1.0, 1e-7);
}

static std::string write_tmp(const std::string& name, const std::string& text) {
  auto p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

TEST(Spectrum, CsvRejectsNonMonotoneWithLine) {
  auto f = write_tmp("ofl_nonmono.csv", "wavelength_nm,v\n400,0.1\n410,0.2\n405,0.3\n");
  try {
    read_spectrum_csv(f);
    FAIL() << "accepted a non-monotone spectrum";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), f);
    EXPECT_EQ(e.field(), "line 4");
  }
}

TEST(Spectrum, CsvRejectsNaNAndNegative) {
  auto f1 = write_tmp("ofl_nan.csv", "wavelength_nm,v\n400,0.1\n410,NaN\n");
  EXPECT_THROW(read_spectrum_csv(f1), InputError);
  auto f2 = write_tmp("ofl_neg.csv", "wavelength_nm,v\n400,0.1\n410,-0.2\n");
  EXPECT_THROW(read_spectrum_csv(f2), InputError);
  SpectrumCsvOptions o;
  o.clip_negative = true;
  auto t = read_spectrum_csv(f2, o);
  EXPECT_EQ(t.value[1], 0.0);
}
