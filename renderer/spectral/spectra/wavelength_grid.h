// The transport wavelength grid, chosen at run time (default 350-830 nm every 5 nm).
// Every spectrum in a render is tabulated on this grid; a spectral value at index i stands for
// the bin [lambda_i - step/2, lambda_i + step/2], so integrals over wavelength are sums times step.
#pragma once
#include <cmath>
#include <string>

namespace ofl {

struct WavelengthGrid {
  double min_nm = 350.0;
  double max_nm = 830.0;
  double step_nm = 5.0;

  int size() const { return static_cast<int>(std::lround((max_nm - min_nm) / step_nm)) + 1; }
  double wavelength(int i) const { return min_nm + step_nm * i; }
  double bin_lo(int i) const { return wavelength(i) - 0.5 * step_nm; }
  double bin_hi(int i) const { return wavelength(i) + 0.5 * step_nm; }
  // Index of the bin holding `nm`, or -1 outside the grid.
  int index_of(double nm) const {
    double f = (nm - min_nm) / step_nm;
    int i = static_cast<int>(std::lround(f));
    return (i < 0 || i >= size()) ? -1 : i;
  }
  bool operator==(const WavelengthGrid& o) const {
    return min_nm == o.min_nm && max_nm == o.max_nm && step_nm == o.step_nm;
  }
  // Empty when valid, otherwise what is wrong (step must divide the range, 2..4096 samples).
  std::string problem() const;
};

inline std::string WavelengthGrid::problem() const {
  if (!(step_nm > 0)) return "step_nm must be positive";
  if (!(max_nm > min_nm)) return "max_nm must be greater than min_nm";
  if (!(min_nm > 0)) return "min_nm must be positive";
  double n = (max_nm - min_nm) / step_nm;
  if (std::fabs(n - std::round(n)) > 1e-6) return "step_nm must divide max_nm - min_nm";
  if (n + 1 > 4096) return "more than 4096 wavelength samples";
  return {};
}

}  // namespace ofl
