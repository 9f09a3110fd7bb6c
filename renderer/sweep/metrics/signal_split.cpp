#include "renderer/sweep/metrics/signal_split.h"

#include <algorithm>
#include <stdexcept>

namespace ofl {

std::vector<bool> led_band_mask(const std::vector<double>& lo, const std::vector<double>& hi, const WavelengthGrid& grid,
                                const std::vector<double>& led, double threshold) {
  double peak = 0;
  for (double v : led) peak = std::max(peak, v);
  std::vector<bool> in(lo.size(), false);
  if (!(peak > 0)) return in;
  for (size_t b = 0; b < lo.size(); ++b)
    for (int i = 0; i < grid.size() && i < int(led.size()); ++i) {
      double nm = grid.wavelength(i);
      if (nm >= lo[b] - 1e-9 && nm <= hi[b] + 1e-9 && led[i] >= threshold * peak) in[b] = true;
    }
  return in;
}

SignalSplit split_signal(const SpectralImage& img, const std::vector<bool>& in_band, const CameraDescription& cam,
                         const FieldGeometry& g) {
  const int B = img.bands();
  if (int(in_band.size()) != B) throw std::invalid_argument("split_signal: band mask size differs from the image's bands");
  SpectralImage fl, refl, leak;
  for (SpectralImage* p : {&fl, &refl, &leak}) {
    p->resize(img.width, img.height, img.band_nm);
    p->attributes = img.attributes;
  }
  const bool has_fl = img.fluorescence.size() == img.data.size();
  for (size_t i = 0; i < img.data.size(); ++i) {
    float f = has_fl ? std::max(0.0f, img.fluorescence[i]) : 0.0f;
    // Monte Carlo noise can make the fluorescent part of a pixel exceed its total by a hair.
    float r = std::max(0.0f, img.data[i] - f);
    fl.data[i] = f;
    if (in_band[i % B]) leak.data[i] = r;
    else refl.data[i] = r;
  }
  SignalSplit s;
  s.fluorescence = expected_electrons(fl, cam, g).mosaic_e;
  s.reflected = expected_electrons(refl, cam, g).mosaic_e;
  s.leak = expected_electrons(leak, cam, g).mosaic_e;
  return s;
}

}  // namespace ofl
