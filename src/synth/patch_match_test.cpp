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

// Everywhere, the borders included, for several patch sizes and sources narrower than a window,
// with a mask: the triangle filter (p - |d|) of the centres' histogram, tap by tap.
TEST(Occupancy, WindowSumsAreTheTriangleFilterEverywhere) {
  CounterRng rng(9);
  for (const int p : {3, 5, 7})
    for (const auto& [sw, sh] : {std::pair{23, 17}, std::pair{4, 9}, std::pair{300, 6}}) {
      const int tw = 19, th = 13;
      Image<int32_t> nnf(tw, th, 2);
      Image<uint8_t> active(tw, th, 1);
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
          nnf(x, y, 0) = int(rng.uniform(uint32_t(sw)));
          nnf(x, y, 1) = int(rng.uniform(uint32_t(sh)));
          active(x, y) = rng.uniform(3) != 0 ? 1 : 0;
        }
      PatchMatchLevel L;
      L.sw = sw, L.sh = sh, L.tw = tw, L.th = th, L.nnf = &nnf, L.active = &active;
      std::vector<int32_t> sums, scratch;
      occupancy_window_sums(L, p, sums, scratch);
      std::vector<int> count(std::size_t(sw) * sh, 0);
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x)
          if (active(x, y)) count[std::size_t(nnf(x, y, 1)) * sw + nnf(x, y, 0)]++;
      for (int cy = 0; cy < sh; ++cy)
        for (int cx = 0; cx < sw; ++cx) {
          int s = 0;
          for (int dy = -(p - 1); dy <= p - 1; ++dy)
            for (int dx = -(p - 1); dx <= p - 1; ++dx) {
              const int x = cx + dx, y = cy + dy;
              if (x >= 0 && y >= 0 && x < sw && y < sh)
                s += (p - std::abs(dx)) * (p - std::abs(dy)) * count[std::size_t(y) * sw + x];
            }
          ASSERT_EQ(sums[std::size_t(cy) * sw + cx], s)
              << "p " << p << " source " << sw << "x" << sh << " at " << cx << "," << cy;
        }
    }
}

}  // namespace
}  // namespace emaki::synth
