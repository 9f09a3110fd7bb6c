// Per output band of a rendered image: the mean over pixels and its standard error (pixels taken as
// independent samples), of all light or of its fluorescent part. For tests comparing two renders band
// by band.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "renderer/image/spectral_image.h"

namespace ofl::test {

struct BandMeans {
  std::vector<double> mean, se;  // per output band
};

inline BandMeans band_means(const SpectralImage& im, bool fluorescence_only) {
  BandMeans m;
  const size_t px = size_t(im.width) * im.height;
  for (int b = 0; b < im.bands(); ++b) {
    double s = 0, s2 = 0;
    for (size_t i = 0; i < px; ++i) {
      const double v = (fluorescence_only ? im.fluorescence : im.data)[i * im.bands() + b];
      s += v;
      s2 += v * v;
    }
    const double mu = s / px;
    m.mean.push_back(mu);
    m.se.push_back(std::sqrt(std::max(0.0, s2 / px - mu * mu) / (px - 1)));
  }
  return m;
}

}  // namespace ofl::test
