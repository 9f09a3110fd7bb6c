#include "renderer/camera/sensor/pixel_rng.h"

#include <array>
#include <cmath>

namespace ofl {
namespace {

constexpr uint64_t kGolden = 0x9E3779B97F4A7C15ull;

uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

constexpr int kTable = 256;
const std::array<double, kTable>& log_factorial_table() {
  static const std::array<double, kTable> t = [] {
    std::array<double, kTable> a{};
    a[0] = 0;
    for (int k = 1; k < kTable; ++k) a[k] = a[k - 1] + std::log(static_cast<double>(k));
    return a;
  }();
  return t;
}

}  // namespace

double log_factorial(uint64_t k) {
  if (k < kTable) return log_factorial_table()[k];
  // Stirling series for ln Gamma(n + 1); the truncation error is below 1e-15 for n >= 256.
  double n = static_cast<double>(k);
  double inv = 1.0 / n, inv2 = inv * inv;
  return (n + 0.5) * std::log(n) - n + 0.91893853320467274178 +
         inv * (1.0 / 12 - inv2 * (1.0 / 360 - inv2 * (1.0 / 1260)));
}

PixelRng::PixelRng(uint64_t seed, NoisePurpose purpose, uint64_t pixel) {
  uint64_t s = mix64(seed + kGolden * (static_cast<uint64_t>(purpose) + 1));
  state_ = mix64(s ^ mix64(pixel + 0xD1B54A32D192ED03ull));
}

uint64_t PixelRng::next_u64() {
  state_ += kGolden;
  return mix64(state_);
}

double PixelRng::uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

double PixelRng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u1 = 1.0 - uniform();  // (0, 1]
  double u2 = uniform();
  double r = std::sqrt(-2.0 * std::log(u1));
  double a = 6.283185307179586 * u2;
  spare_ = r * std::sin(a);
  has_spare_ = true;
  return r * std::cos(a);
}

uint64_t PixelRng::poisson(double mean) {
  if (!(mean > 0)) return 0;
  if (mean < 12.0) {
    // Inversion by multiplying uniforms: the count of uniforms whose running product stays above e^-mean.
    double limit = std::exp(-mean), p = 1.0;
    uint64_t k = 0;
    for (;;) {
      p *= uniform();
      if (p <= limit) return k;
      ++k;
    }
  }
  // PTRS: transformed rejection with squeeze (Hoermann 1993).
  const double slam = std::sqrt(mean), loglam = std::log(mean);
  const double b = 0.931 + 2.53 * slam;
  const double a = -0.059 + 0.02483 * b;
  const double inv_alpha = 1.1239 + 1.1328 / (b - 3.4);
  const double vr = 0.9277 - 3.6224 / (b - 2.0);
  for (;;) {
    double u = uniform() - 0.5;
    double v = uniform();
    double us = 0.5 - std::fabs(u);
    double kf = std::floor((2.0 * a / us + b) * u + mean + 0.43);
    if (us >= 0.07 && v <= vr) return static_cast<uint64_t>(kf);
    if (kf < 0 || (us < 0.013 && v > us)) continue;
    uint64_t k = static_cast<uint64_t>(kf);
    if (std::log(v) + std::log(inv_alpha) - std::log(a / (us * us) + b) <= -mean + kf * loglam - log_factorial(k))
      return k;
  }
}

}  // namespace ofl
