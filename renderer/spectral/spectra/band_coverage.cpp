#include "renderer/spectral/spectra/band_coverage.h"

#include <algorithm>
#include <cstdio>

namespace ofl {

BandCoverage band_coverage(const WavelengthGrid& grid, const std::vector<double>& values,
                           const std::vector<double>& band_lo, const std::vector<double>& band_hi) {
  BandCoverage c;
  double outside = 0;
  bool any = false;
  for (int i = 0; i < grid.size() && i < static_cast<int>(values.size()); ++i) {
    double a = grid.bin_lo(i), b = grid.bin_hi(i), v = values[i] * (b - a);
    double covered = 0;
    for (size_t k = 0; k < band_lo.size(); ++k) covered += std::max(0.0, std::min(b, band_hi[k]) - std::max(a, band_lo[k]));
    double out = v * std::max(0.0, 1.0 - covered / (b - a));
    c.total += v;
    outside += out;
    if (out > 0) {
      if (!any) c.outside_lo_nm = a;
      c.outside_hi_nm = b;
      any = true;
    }
  }
  c.outside_share = c.total > 0 ? outside / c.total : 0.0;
  return c;
}

std::string coverage_warning(const BandCoverage& c, const std::string& what, double bands_lo_nm, double bands_hi_nm,
                             double tolerance) {
  if (!(c.outside_share > tolerance)) return "";
  char b[320];
  std::snprintf(b, sizeof b, "%.1f %% of %s (%.1f-%.1f nm) lies outside the image's bands %.1f-%.1f nm and is lost",
                100.0 * c.outside_share, what.c_str(), c.outside_lo_nm, c.outside_hi_nm, bands_lo_nm, bands_hi_nm);
  return b;
}

}  // namespace ofl
