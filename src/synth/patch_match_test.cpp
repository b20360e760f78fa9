// PatchMatch's occupancy (uniformity) bookkeeping.
#include "synth/patch_match.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "synth/test_images.h"

namespace emaki::synth {
namespace {

using namespace test;

TEST(Occupancy, WindowSumsMatchBruteForce) {
  const int sw = 20, sh = 16, tw = 12, th = 10, p = 5;
  Image<int32_t> nnf(tw, th, 2);
  CounterRng rng(3);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      nnf(x, y, 0) = 2 + int(rng.uniform(sw - 4));
      nnf(x, y, 1) = 2 + int(rng.uniform(sh - 4));
    }
  PatchMatchLevel L;
  L.sw = sw, L.sh = sh, L.tw = tw, L.th = th, L.nnf = &nnf;
  std::vector<int32_t> sums, scratch;
  occupancy_window_sums(L, p, sums, scratch);
  // Brute force: omega(s) = target patches covering s; window sum = sum of omega over the patch.
  std::vector<int> omega(sw * sh, 0);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) omega[(nnf(x, y, 1) + dy) * sw + nnf(x, y, 0) + dx]++;
  for (int cy = 2; cy < sh - 2; ++cy)
    for (int cx = 2; cx < sw - 2; ++cx) {
      int s = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) s += omega[(cy + dy) * sw + cx + dx];
      ASSERT_EQ(sums[cy * sw + cx], s) << cx << "," << cy;
    }
}

}  // namespace
}  // namespace emaki::synth
