// PCG32 random numbers (O'Neill 2014, the published constants) with one independent stream per
// pixel and sample: the stream is a pure function of (seed, pixel, sample index), which is what
// makes images bit-identical whatever the number of threads.
#pragma once
#include <cstdint>

namespace ofl {

class Rng {
 public:
  Rng(uint64_t seed, uint64_t stream) { init(seed, stream); }

  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }
  // Uniform in [0, 1), never 1.
  float next_float() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }
  double next_double() { return (static_cast<double>(next_u32() >> 5) * 67108864.0 + (next_u32() >> 6)) * 0x1p-53; }

  // A stream id for (pixel, sample) that no other pair shares.
  static uint64_t stream_for(uint64_t pixel, uint64_t sample) { return mix(pixel * 0x9E3779B97F4A7C15ULL ^ mix(sample + 0x632BE59BD9B4E019ULL)); }

 private:
  static uint64_t mix(uint64_t z) {  // splitmix64 finaliser
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  void init(uint64_t seed, uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    next_u32();
    state_ += mix(seed);
    next_u32();
  }
  uint64_t state_ = 0, inc_ = 1;
};

}  // namespace ofl
