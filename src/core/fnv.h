// FNV-1a, 64-bit: the digest of the shot's names, manifests and file contents. Fast, and only
// ever compared with itself (not a security boundary: a changed file is redone, a forged one is
// the user's own).
#pragma once

#include <cstddef>
#include <cstdint>
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

}  // namespace emaki
