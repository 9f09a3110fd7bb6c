// Counter-based random numbers for the sensor noise: every (seed, purpose, pixel) triple starts its
// own SplitMix64 stream, so a pixel's noise does not depend on which thread simulates it or in
// which order (same seed -> same raw with any --threads). Poisson variates use inversion for small
// means and Hoermann's PTRS transformed rejection (W. Hoermann, "The transformed rejection method
// for generating Poisson random variables", Insurance: Mathematics and Economics 12, 1993) above;
// both are exact, so shot-noise statistics hold at every signal level.
#pragma once
#include <cstdint>

namespace ofl {

enum class NoisePurpose : uint64_t { kPrnu = 1, kDsnu = 2, kTemporal = 3 };

class PixelRng {
 public:
  PixelRng(uint64_t seed, NoisePurpose purpose, uint64_t pixel);
  uint64_t next_u64();
  double uniform();   // [0, 1), 53 random bits
  double normal();    // standard normal (Box-Muller)
  uint64_t poisson(double mean);

 private:
  uint64_t state_;
  double spare_ = 0;
  bool has_spare_ = false;
};

// ln(k!) without the global state lgamma touches (thread safe).
double log_factorial(uint64_t k);

}  // namespace ofl
