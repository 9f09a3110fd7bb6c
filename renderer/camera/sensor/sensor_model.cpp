#include "renderer/camera/sensor/sensor_model.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "renderer/camera/sensor/pixel_rng.h"

namespace ofl {

FixedPattern make_fixed_pattern(const SensorDescription& s, int w, int h) {
  FixedPattern f;
  size_t n = static_cast<size_t>(w) * h;
  if (s.prnu > 0) f.prnu_gain.resize(n);
  if (s.dsnu_e > 0) f.dsnu_e.resize(n);
  if (f.prnu_gain.empty() && f.dsnu_e.empty()) return f;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      if (!f.prnu_gain.empty()) {
        PixelRng rng(s.fixed_pattern_seed, NoisePurpose::kPrnu, i);
        f.prnu_gain[i] = static_cast<float>(std::max(0.0, 1.0 + s.prnu * rng.normal()));
      }
      if (!f.dsnu_e.empty()) {
        PixelRng rng(s.fixed_pattern_seed, NoisePurpose::kDsnu, i);
        f.dsnu_e[i] = static_cast<float>(s.dsnu_e * rng.normal());
      }
    }
  });
  return f;
}

namespace {
// Steps 4-7, also reporting which clip acted.
uint16_t digitise_counted(double e, const SensorDescription& s, bool* full_well, bool* adc) {
  *full_well = e > s.full_well_e;
  if (*full_well) e = s.full_well_e;
  double dn = std::floor(e * s.total_gain() + 0.5) + s.black_level_dn;
  *adc = dn > s.adc_max_dn();
  return static_cast<uint16_t>(std::clamp(dn, 0.0, static_cast<double>(s.adc_max_dn())));
}
}  // namespace

uint16_t digitise(double e, const SensorDescription& s) {
  bool fw, adc;
  return digitise_counted(e, s, &fw, &adc);
}

RawFrame simulate_raw(const std::vector<float>& mu, int w, int h, const SensorDescription& s, bool noise,
                      uint64_t seed, const FixedPattern& fixed) {
  RawFrame out;
  out.width = w;
  out.height = h;
  out.dn.assign(static_cast<size_t>(w) * h, 0);
  const double dark = s.dark_electrons();
  std::atomic<size_t> fw_count{0}, adc_count{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    size_t fw_local = 0, adc_local = 0;
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < w; ++x) {
        size_t i = static_cast<size_t>(y) * w + x;
        double e;
        if (noise) {
          PixelRng rng(seed, NoisePurpose::kTemporal, i);
          double mp = mu[i] * (fixed.prnu_gain.empty() ? 1.0 : fixed.prnu_gain[i]);
          e = static_cast<double>(rng.poisson(mp)) + static_cast<double>(rng.poisson(dark));
          if (!fixed.dsnu_e.empty()) e += fixed.dsnu_e[i];
          if (s.read_noise_e > 0) e += s.read_noise_e * rng.normal();
        } else {
          e = mu[i] + dark;
        }
        bool fw, adc;
        out.dn[i] = digitise_counted(e, s, &fw, &adc);
        fw_local += fw;
        adc_local += adc && !fw;
      }
    fw_count += fw_local;
    adc_count += adc_local;
  });
  out.full_well_clipped = fw_count;
  out.adc_clipped = adc_count;
  return out;
}

}  // namespace ofl
