#include "renderer/image/spectral_image.h"

namespace ofl {

std::vector<double> SpectralImage::band_lo() const {
  std::vector<double> lo(band_nm.size());
  for (size_t i = 0; i < band_nm.size(); ++i) {
    double half = band_nm.size() == 1 ? 5.0
                  : i > 0 ? 0.5 * (band_nm[i] - band_nm[i - 1]) : 0.5 * (band_nm[1] - band_nm[0]);
    lo[i] = band_nm[i] - half;
  }
  return lo;
}

std::vector<double> SpectralImage::band_hi() const {
  std::vector<double> hi(band_nm.size());
  size_t n = band_nm.size();
  for (size_t i = 0; i < n; ++i) {
    double half = n == 1 ? 5.0 : i + 1 < n ? 0.5 * (band_nm[i + 1] - band_nm[i]) : 0.5 * (band_nm[n - 1] - band_nm[n - 2]);
    hi[i] = band_nm[i] + half;
  }
  return hi;
}

}  // namespace ofl
