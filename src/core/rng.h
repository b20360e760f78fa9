// Counter-based random numbers: a value is a hash of (seed, stream...) so results never depend
// on which thread asks or in what order. No shared generator state.
#pragma once

#include <cstdint>

namespace emaki {

// SplitMix64 finaliser: a strong 64-bit mix.
inline constexpr uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

inline constexpr uint64_t hash_key(uint64_t seed, uint64_t a, uint64_t b = 0, uint64_t c = 0) {
  return mix64(mix64(mix64(seed ^ mix64(a)) ^ b) ^ c);
}

// A small generator seeded from a hash key; used for one pixel's sequence of draws.
class CounterRng {
 public:
  explicit constexpr CounterRng(uint64_t key) : state_(key) {}
  constexpr uint32_t next_u32() {
    state_ += 0x9e3779b97f4a7c15ull;
    return uint32_t(mix64(state_) >> 32);
  }
  // Uniform integer in [0, n), n > 0 (Lemire's multiply-shift; bias < 2^-32 * n).
  constexpr uint32_t uniform(uint32_t n) { return uint32_t((uint64_t(next_u32()) * n) >> 32); }
  constexpr float uniform_float() { return float(next_u32() >> 8) * (1.0f / 16777216.0f); }

 private:
  uint64_t state_;
};

}  // namespace emaki
