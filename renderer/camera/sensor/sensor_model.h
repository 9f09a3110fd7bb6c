// The stochastic half of the camera: the EMVA 1288 linear sensor model, expected electrons -> raw.
// Per pixel, in this order:
//   1. photo-electrons  n_p ~ Poisson(mu_p * g_i)       g_i = 1 + PRNU * N(0,1), a fixed per-pixel gain
//      (PRNU is a variation of the pixel's quantum efficiency, so it acts on the expected signal and
//      the shot noise stays Poisson);
//   2. dark electrons   n_d ~ Poisson(I_dark(T) * t)    I_dark doubles every dark_current_doubling_C;
//   3. e = n_p + n_d + o_i + sigma_read * N(0,1)        o_i = DSNU * N(0,1), a fixed per-pixel offset;
//   4. full-well clip   e = min(e, full_well_e);
//   5. gain and quantisation  DN = round(e * K * analog_gain);
//   6. black level      DN += black_level_dn;
//   7. ADC clip         DN = clamp(DN, 0, 2^bit_depth - 1).
// With noise off, steps 1-3 use the expected values (no shot, dark-shot or read noise, no fixed
// pattern); 4-7 still apply. The fixed pattern (PRNU, DSNU) is seeded by the sensor's
// fixed_pattern_seed and is the same in every frame; the temporal noise is seeded per frame.
#pragma once
#include <cstdint>
#include <vector>

#include "renderer/camera/description/camera_description.h"

namespace ofl {

struct FixedPattern {
  std::vector<float> prnu_gain;  // per pixel, empty when PRNU is 0
  std::vector<float> dsnu_e;     // per pixel, empty when DSNU is 0
};
FixedPattern make_fixed_pattern(const SensorDescription& s, int width, int height);

// Steps 4-7 for a charge of `electrons`.
uint16_t digitise(double electrons, const SensorDescription& s);

struct RawFrame {
  int width = 0, height = 0;
  std::vector<uint16_t> dn;          // row-major mosaic
  size_t full_well_clipped = 0;      // pixels whose charge was clipped at full well
  size_t adc_clipped = 0;            // pixels clipped at 2^bits - 1 by the ADC (before full well)
  size_t saturated() const { return full_well_clipped + adc_clipped; }
};

// `mosaic_photo_e`: expected photo-electrons of each pixel's own CFA channel (ExpectedSignal::mosaic_e).
RawFrame simulate_raw(const std::vector<float>& mosaic_photo_e, int width, int height, const SensorDescription& s,
                      bool noise, uint64_t seed, const FixedPattern& fixed);

}  // namespace ofl
