// Pyramid: guides are low-passed so thin lines survive, sizes halve, level counts.
#include "synth/pyramid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "synth/synthesizer.h"
#include "synth/test_images.h"

namespace emaki::synth {
namespace {

using namespace test;

TEST(Pyramid, ThinLineSurvivesDownsampling) {
  // A one-pixel vertical line at an odd column: decimation would drop it entirely.
  Image<float> im(64, 8, 1);
  for (int y = 0; y < 8; ++y) im(33, y) = 1.0f;
  Image<float> cur = im.clone();
  for (int level = 0; level < 3; ++level) cur = downsample(cur.cview());
  float peak = 0.0f, total = 0.0f;
  for (int y = 0; y < cur.height(); ++y)
    for (int x = 0; x < cur.width(); ++x) peak = std::max(peak, cur(x, y)), total += cur(x, y);
  EXPECT_GT(peak, 0.05f);
  // The filter keeps the mean: 8 line pixels over 64x8 -> mean 1/64.
  EXPECT_NEAR(total / float(cur.width() * cur.height()), 1.0f / 64.0f, 1e-3f);
}

TEST(Pyramid, ConstantStaysConstantAndSizesHalve) {
  Image<int16_t> im(37, 20, 8);
  im.fill(1234);
  Image<int16_t> d = downsample(im.cview());
  EXPECT_EQ(d.width(), 19);
  EXPECT_EQ(d.height(), 10);
  for (int y = 0; y < d.height(); ++y)
    for (int x = 0; x < d.width(); ++x)
      for (int c = 0; c < 8; ++c) ASSERT_EQ(d(x, y, c), 1234);
}

TEST(Pyramid, LevelCountFollowsPatchSize) {
  EXPECT_EQ(max_pyramid_levels(1200, 912, 1200, 912, 5), 7);
  EXPECT_EQ(max_pyramid_levels(20, 20, 20, 20, 5), 1);
}

// The [1 3 3 1] / 8 filter each way, borders clamped, integers rounded half away from zero
// (std::lround): odd and even sizes, 1 to 16 channels, negative values and exact halves.
TEST(Pyramid, DownsampleIsTheFilterTapByTap) {
  CounterRng rng(21);
  for (const int c : {1, 3, 8, 16})
    for (const auto& [w, h] : {std::pair{9, 7}, std::pair{16, 10}, std::pair{1, 5}}) {
      Image<int16_t> ints(w, h, c);
      Image<float> floats(w, h, c);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int k = 0; k < c; ++k) {
            // Multiples of 4 from -64 to 60 give sums that land on halves.
            ints(x, y, k) = int16_t(4 * int(rng.uniform(32)) - 64);
            floats(x, y, k) = rng.uniform_float() * 2.0f - 1.0f;
          }
      const Image<int16_t> di = downsample(ints.cview());
      const Image<float> df = downsample(floats.cview());
      const int ow = (w + 1) / 2, oh = (h + 1) / 2;
      ASSERT_EQ(di.width(), ow);
      ASSERT_EQ(di.height(), oh);
      const auto filter = [&](const auto& im, int x, int y, int k) {
        float rows[4];
        for (int j = 0; j < 4; ++j) {
          const int v = std::clamp(2 * y - 1 + j, 0, h - 1);
          const auto at = [&](int u) { return float(im(std::clamp(u, 0, w - 1), v, k)); };
          rows[j] =
              (at(2 * x - 1) + 3.0f * at(2 * x) + 3.0f * at(2 * x + 1) + at(2 * x + 2)) * 0.125f;
        }
        return (rows[0] + 3.0f * rows[1] + 3.0f * rows[2] + rows[3]) * 0.125f;
      };
      for (int y = 0; y < oh; ++y)
        for (int x = 0; x < ow; ++x)
          for (int k = 0; k < c; ++k) {
            ASSERT_EQ(di(x, y, k), int16_t(std::lround(filter(ints, x, y, k))))
                << c << " channels " << w << "x" << h << " at " << x << "," << y;
            ASSERT_EQ(df(x, y, k), filter(floats, x, y, k));
          }
    }
}

}  // namespace
}  // namespace emaki::synth
