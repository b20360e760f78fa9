// Pyramid: guides are low-passed so thin lines survive, sizes halve, level counts.
#include "synth/pyramid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
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

}  // namespace
}  // namespace emaki::synth
