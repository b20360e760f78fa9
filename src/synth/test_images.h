// Small synthetic images shared by the engine's unit tests.
#pragma once

#include <cstring>

#include "core/image.h"
#include "core/rng.h"

namespace emaki::synth::test {

inline Image<float> noise(int w, int h, int c, uint64_t seed) {
  Image<float> im(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) {
        CounterRng rng(hash_key(seed, uint64_t(y) * 4096 + x, uint64_t(k)));
        im(x, y, k) = rng.uniform_float();
      }
  return im;
}

// A smooth guide plus noise: unique patches, so the identity is the only perfect match.
inline Image<float> textured(int w, int h, uint64_t seed) {
  Image<float> im = noise(w, h, 3, seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      im(x, y, 0) = 0.5f * im(x, y, 0) + 0.5f * float(x) / float(w);
      im(x, y, 1) = 0.5f * im(x, y, 1) + 0.5f * float(y) / float(h);
    }
  return im;
}

inline bool same_bits(const Image<float>& a, const Image<float>& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels())
    return false;
  for (int y = 0; y < a.height(); ++y)
    if (std::memcmp(a.row(y), b.row(y), sizeof(float) * a.width() * a.channels()) != 0)
      return false;
  return true;
}

}  // namespace emaki::synth::test
