// temporal_sharpening(): the share of the frame's pixels against the painting's sets a temporal
// layer's guide low-pass and sharp estimate, unless the layer sets them.
#include "pipeline/temporal_guide.h"

#include <gtest/gtest.h>

namespace emaki::pipeline {
namespace {

TEST(TemporalSharpening, FollowsTheFramesShareOfThePaintingsPixels) {
  TemporalSpec t;
  EXPECT_EQ(temporal_sharpening(t, 960, 540, 1200, 912).sharp_estimate, 0.0f);  // off by default
  t.sharp_estimate = -1.0f;
  // The StyLit painting (1200x912) under the Fox example's sizes and the town's.
  TemporalSharpening s = temporal_sharpening(t, 480, 270, 1200, 912);
  EXPECT_EQ(s.guide_sigma, 0.0f);
  EXPECT_EQ(s.sharp_estimate, 0.0f);
  s = temporal_sharpening(t, 960, 540, 1200, 912);
  EXPECT_EQ(s.guide_sigma, 1.0f);
  EXPECT_EQ(s.sharp_estimate, 1.0f);
  s = temporal_sharpening(t, 640, 360, 1200, 912);  // 21 % of the painting's pixels
  EXPECT_NEAR(s.guide_sigma, (640.0 * 360 / (1200.0 * 912) - 0.12) / 0.28, 1e-6);
  EXPECT_EQ(s.sharp_estimate, s.guide_sigma);
  // The same share at half the size: a lookdev preview with its painting halved.
  s = temporal_sharpening(t, 480, 270, 600, 456);
  EXPECT_EQ(s.sharp_estimate, 1.0f);
  EXPECT_EQ(temporal_sharpening(t, 960, 540, 0, 0).guide_sigma, 0.0f);
}

TEST(TemporalSharpening, ALayerWithoutATemporalGuideOrWithItsOwnKeysKeepsThem) {
  TemporalSpec t;
  t.weight = 0.0f;  // the shadow and outline kinds: no temporal guide
  TemporalSharpening s = temporal_sharpening(t, 960, 540, 1200, 912);
  EXPECT_EQ(s.guide_sigma, 0.0f);
  EXPECT_EQ(s.sharp_estimate, 0.0f);
  t.weight = 1.0f;
  t.guide_sigma = 2.5f;
  t.sharp_estimate = 0.0f;
  s = temporal_sharpening(t, 960, 540, 1200, 912);
  EXPECT_EQ(s.guide_sigma, 2.5f);
  EXPECT_EQ(s.sharp_estimate, 0.0f);
}

}  // namespace
}  // namespace emaki::pipeline
