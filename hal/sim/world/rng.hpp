// Deterministic random numbers for scene generation and sensor noise. Implemented here (not
// with <random> distributions) so that the same seed gives the same scene and the same bytes with
// every standard library.
#pragma once

#include <cstdint>

namespace sh::render {

// SplitMix64 finaliser: a strong 64-bit mix, also used as a counter-based hash.
inline uint64_t Mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}

  uint64_t Next() {
    state_ += 0x9e3779b97f4a7c15ull;
    return Mix64(state_);
  }
  // Uniform in [0, 1) with 24 random bits (exact in float).
  float Uniform() { return static_cast<float>(Next() >> 40) * (1.0f / 16777216.0f); }
  float Uniform(float lo, float hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [0, n), n > 0 (multiply-shift; bias below 2^-32 for small n).
  int Below(int n) { return static_cast<int>(((Next() >> 32) * static_cast<uint64_t>(n)) >> 32); }

 private:
  uint64_t state_;
};

// Approximately standard-normal value from a 64-bit hash value and two more derived from it:
// the sum of twelve 16-bit uniforms minus 6 (Irwin-Hall; exact mean 0 and variance 1, tails cut at
// 6 sigma). Integer arithmetic, so the result is the same everywhere.
inline float GaussianFromHash(uint64_t h) {
  uint32_t sum = 0;
  for (int k = 0; k < 3; ++k) {
    h = Mix64(h + 0x9e3779b97f4a7c15ull);
    sum += static_cast<uint32_t>(h & 0xffff) + static_cast<uint32_t>((h >> 16) & 0xffff) +
           static_cast<uint32_t>((h >> 32) & 0xffff) + static_cast<uint32_t>(h >> 48);
  }
  // Each 16-bit value has mean 32767.5; twelve of them have mean 393210.
  return (static_cast<float>(sum) - 393210.0f) * (1.0f / 65536.0f);
}

}  // namespace sh::render
