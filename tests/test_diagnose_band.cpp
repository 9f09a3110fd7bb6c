// Diagnose: the unknown band's shape (lognormal_band, forward_model.h) against its definition,
// measured on a fine grid (250-2500 nm) independently of the closed forms the function uses: unit area, the
// energy-per-nm maximum at peak_nm, and in wavenumber a FWHM of 1e7 fwhm/peak^2 split in the ratio
// `asymmetry` (low- to high-wavenumber half width); asymmetry 1 is the Gaussian in wavenumber and
// the shape is continuous there.
#include <gtest/gtest.h>

#include <cmath>

#include "renderer/diagnose/spectra/forward_model.h"

using namespace ofl;

namespace {

struct Measured {
  double area = 0, peak_nm = 0, fwhm_wn = 0, ratio = 0;
};

Measured measure(double peak, double fwhm, double rho) {
  WavelengthGrid g{250, 2500, 0.005};
  auto v = lognormal_band(g, peak, fwhm, rho);
  Measured m;
  int ip = 0;
  for (int i = 0; i < g.size(); ++i) {
    m.area += v[i];
    if (v[i] > v[ip]) ip = i;
  }
  m.peak_nm = g.wavelength(ip);
  // Per unit wavenumber: v / step * l^2 / 1e7. Its maximum and half-maximum crossings.
  auto per_wn = [&](int i) { return v[i] / g.step_nm * g.wavelength(i) * g.wavelength(i) / 1e7; };
  int iw = 0;
  for (int i = 0; i < g.size(); ++i)
    if (per_wn(i) > per_wn(iw)) iw = i;
  double half = 0.5 * per_wn(iw);
  int lo = iw, hi = iw;  // lo: shorter wavelength (higher wavenumber)
  while (lo > 0 && per_wn(lo) > half) --lo;
  while (hi + 1 < g.size() && per_wn(hi) > half) ++hi;
  double nu_peak = 1e7 / g.wavelength(iw), nu_hi = 1e7 / g.wavelength(lo), nu_lo = 1e7 / g.wavelength(hi);
  m.fwhm_wn = nu_hi - nu_lo;
  m.ratio = (nu_peak - nu_lo) / (nu_hi - nu_peak);
  return m;
}

}  // namespace

TEST(DiagnoseBand, LogNormalBandHasItsAreaPeakWidthAndAsymmetry) {
  for (double peak : {480.0, 600.0, 680.0})
    for (double fwhm : {12.0, 45.0, 120.0})
      for (double rho : {0.5, 0.8, 1.0, 1.3, 2.2}) {
        SCOPED_TRACE("peak " + std::to_string(peak) + " fwhm " + std::to_string(fwhm) + " rho " + std::to_string(rho));
        Measured m = measure(peak, fwhm, rho);
        // Unit area where the band lies inside the grid; the widest, most skewed bands keep a
        // log-normal tail beyond it (a few % at 120 nm FWHM, rho 2.2), never more than the whole.
        if (fwhm <= 45 || (rho >= 0.8 && rho <= 1.3))
          EXPECT_NEAR(m.area, 1.0, 2e-3);
        else
          EXPECT_TRUE(m.area > 0.95 && m.area < 1.0 + 1e-3) << m.area;
        EXPECT_NEAR(m.peak_nm, peak, 0.02);
        double H = 1e7 * fwhm / (peak * peak);
        EXPECT_NEAR(m.fwhm_wn / H, 1.0, 5e-3);
        EXPECT_NEAR(m.ratio / rho, 1.0, 0.01 + 0.002 * H / fwhm);
      }
}

TEST(DiagnoseBand, AsymmetryOneIsTheGaussianInWavenumberAndContinuous) {
  WavelengthGrid g{350, 900, 0.5};
  auto gauss = lognormal_band(g, 620, 60, 1.0);
  for (double rho : {1.0 + 1e-5, 1.0 - 1e-5, 1.001}) {
    auto near = lognormal_band(g, 620, 60, rho);
    double dmax = 0, vmax = 0;
    for (int i = 0; i < g.size(); ++i) {
      dmax = std::max(dmax, std::fabs(near[i] - gauss[i]));
      vmax = std::max(vmax, gauss[i]);
    }
    EXPECT_LT(dmax / vmax, rho == 1.001 ? 2e-3 : 2e-5) << rho;
  }
  // The Gaussian branch against the textbook Gaussian in wavenumber, normalised per nm.
  double nu_p = 1e7 / 620, H = 1e7 * 60 / (620.0 * 620.0), s = H / (2 * std::sqrt(2 * std::log(2.0)));
  double nu0 = nu_p - 2 * s * s / nu_p;  // the per-nm maximum lies 2 s^2 / nu above nu0
  for (int i = 0; i < g.size(); i += 37) {
    double l = g.wavelength(i), nu = 1e7 / l;
    double ref = std::exp(-0.5 * (nu - nu0) * (nu - nu0) / (s * s)) / (s * std::sqrt(2 * M_PI)) * 1e7 / (l * l) * g.step_nm;
    EXPECT_NEAR(gauss[i], ref, 1e-9 + 1e-6 * ref);
  }
}
