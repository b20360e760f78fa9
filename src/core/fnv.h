// FNV-1a, 64-bit: the digest of the shot's names, manifests and file contents. Fast, and only
// ever compared with itself (not a security boundary: a changed file is redone, a forged one is
// the user's own).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

namespace emaki {

inline constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ull;
inline constexpr uint64_t kFnvPrime = 0x100000001b3ull;

// One value (a byte, or a 32-bit word for bit patterns) folded into the digest `h`.
inline constexpr uint64_t fnv1a_add(uint64_t h, uint32_t value) {
  return (h ^ value) * kFnvPrime;
}

// The bytes of `s` folded into `h` (kFnvOffset to start).
inline uint64_t fnv1a(std::string_view s, uint64_t h = kFnvOffset) {
  for (const char c : s) h = fnv1a_add(h, static_cast<unsigned char>(c));
  return h;
}

// A digest of many bytes in four independent chains, so that the multiplier is kept busy (one
// chain waits on each multiply): add() folds each whole 32 bytes as four 64-bit words, one per
// chain, and the 32-bit words left over into the first chain (any last 1-3 bytes are ignored:
// callers digest whole words); value() folds the chains together.
class FnvLanes {
 public:
  void add(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    const auto mix = [](uint64_t h, uint64_t w) { return (h ^ w) * kFnvPrime; };
    std::size_t i = 0;
    for (; i + 32 <= size; i += 32) {
      uint64_t w[4];
      std::memcpy(w, p + i, sizeof w);
      for (int k = 0; k < 4; ++k) lane_[k] = mix(lane_[k], w[k]);
    }
    for (; i + 4 <= size; i += 4) {
      uint32_t w;
      std::memcpy(&w, p + i, 4);
      lane_[0] = mix(lane_[0], w);
    }
  }
  // The chains folded into `h`.
  uint64_t value(uint64_t h = kFnvOffset) const {
    for (const uint64_t l : lane_) h = (h ^ l) * kFnvPrime;
    return h;
  }

 private:
  uint64_t lane_[4] = {kFnvOffset, kFnvOffset ^ 1, kFnvOffset ^ 2, kFnvOffset ^ 3};
};

}  // namespace emaki
