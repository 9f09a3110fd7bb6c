#include "renderer/spectral/color.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "renderer/core/files/asset_path.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {
namespace {
struct Cmf {
  Spectrum x, y, z;
};
const Cmf& cmf() {
  static Cmf c;
  static std::once_flag once;
  std::call_once(once, [] {
    auto file = asset_path("spectra/cie/cie1931_xyz_2deg.csv");
    SpectrumCsvOptions o;
    o.column = "xbar"; c.x = table_spectrum(read_spectrum_csv(file, o), "xbar");
    o.column = "ybar"; c.y = table_spectrum(read_spectrum_csv(file, o), "ybar");
    o.column = "zbar"; c.z = table_spectrum(read_spectrum_csv(file, o), "zbar");
  });
  return c;
}
}  // namespace

ColorMatching cie1931_on_grid(const WavelengthGrid& grid) {
  return {tabulate(cmf().x, grid), tabulate(cmf().y, grid), tabulate(cmf().z, grid)};
}

ColorMatching cie1931_on_bands(const std::vector<double>& lo, const std::vector<double>& hi) {
  ColorMatching m;
  for (size_t i = 0; i < lo.size(); ++i) {
    m.x.push_back(average(cmf().x, lo[i], hi[i]));
    m.y.push_back(average(cmf().y, lo[i], hi[i]));
    m.z.push_back(average(cmf().z, lo[i], hi[i]));
  }
  return m;
}

std::array<double, 3> xyz_to_linear_srgb(const std::array<double, 3>& c) {
  // IEC 61966-2-1 matrix (D65 white).
  return {3.2404542 * c[0] - 1.5371385 * c[1] - 0.4985314 * c[2],
          -0.9692660 * c[0] + 1.8760108 * c[1] + 0.0415560 * c[2],
          0.0556434 * c[0] - 0.2040259 * c[1] + 1.0572252 * c[2]};
}

double srgb_encode(double v) {
  v = std::clamp(v, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

}  // namespace ofl
