// temporal_sharpening(): the share of the frame's pixels against the painting's sets a temporal
// layer's guide low-pass and sharp estimate, unless the layer sets them.
#include "pipeline/temporal_guide.h"

#include <gtest/gtest.h>

#include <vector>

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

TEST(TemporalSharpening, CoherenceRadiusGrowsWithTheShare) {
  TemporalSpec t;
  EXPECT_EQ(temporal_sharpening(t, 960, 540, 1200, 912).coherence_radius, 0);  // off by default
  t.coherence_radius = -1;                                                     // the base kind's
  EXPECT_EQ(temporal_sharpening(t, 480, 270, 1200, 912).coherence_radius, 0);
  EXPECT_EQ(temporal_sharpening(t, 640, 360, 1200, 912).coherence_radius, 1);  // 3 x 0.32
  EXPECT_EQ(temporal_sharpening(t, 960, 540, 1200, 912).coherence_radius, 3);
  EXPECT_EQ(temporal_sharpening(t, 480, 270, 600, 456).coherence_radius, 3);
  t.weight = 0.0f;
  EXPECT_EQ(temporal_sharpening(t, 960, 540, 1200, 912).coherence_radius, 0);
  t.weight = 1.0f;
  t.coherence_radius = 2;
  EXPECT_EQ(temporal_sharpening(t, 480, 270, 1200, 912).coherence_radius, 2);
}

// temporal_uniformity(): the kind's flat-area uniformity joins the main transfer's as a map over
// the large flat areas of the layer's guides, and nothing changes where there are none.
TEST(TemporalUniformity, AddsTheFlatAreasTermAsAMap) {
  TemporalSpec t;
  t.uniformity = 0.0f;
  t.flat_uniformity = 500.0f;
  t.flat.area_radius = 8;
  std::vector<Image<float>> guides;
  guides.emplace_back(64, 40, 1);  // zeros: flat everywhere
  synth::Params p;
  Image<float> map;
  temporal_uniformity(t, guides, {}, p, map);
  EXPECT_EQ(p.uniformity, 500.0f);
  ASSERT_TRUE(p.uniformity_map.has_value());
  EXPECT_EQ(map(30, 20), 1.0f);
  // Stripes: no pixel is flat, so no map and no term.
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 64; ++x) guides[0](x, y) = float(x % 2);
  synth::Params q;
  Image<float> none;
  temporal_uniformity(t, guides, {}, q, none);
  EXPECT_EQ(q.uniformity, 0.0f);
  EXPECT_FALSE(q.uniformity_map.has_value());
  EXPECT_TRUE(none.empty());
  // With a uniformity everywhere the map is its share of the total outside the flat areas.
  t.uniformity = 1000.0f;
  guides[0].fill(0.0f);
  for (int y = 0; y < 40; ++y)
    for (int x = 40; x < 64; ++x) guides[0](x, y) = float(x % 2);
  synth::Params r;
  temporal_uniformity(t, guides, {}, r, map);
  EXPECT_EQ(r.uniformity, 1500.0f);
  EXPECT_FLOAT_EQ(map(60, 20), 1000.0f / 1500.0f);
  EXPECT_EQ(map(10, 20), 1.0f);
  t.flat_uniformity = 0.0f;  // the base kind: as before
  synth::Params b;
  temporal_uniformity(t, guides, {}, b, map);
  EXPECT_EQ(b.uniformity, 1000.0f);
  EXPECT_FALSE(b.uniformity_map.has_value());
}

}  // namespace
}  // namespace emaki::pipeline
