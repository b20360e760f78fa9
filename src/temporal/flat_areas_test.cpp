// Flat areas of a layer's guides (where the temporal chain's uniformity acts).
#include "temporal/flat_areas.h"

#include <gtest/gtest.h>

#include "core/rng.h"

namespace emaki::temporal {
namespace {

constexpr int kW = 96, kH = 48;

// Flat at 0.4 left of x = 48, random values right of it.
Image<float> half_flat() {
  Image<float> g(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      CounterRng rng(hash_key(7, uint64_t(x), uint64_t(y)));
      g(x, y) = x < 48 ? 0.4f : float(rng.uniform(1000u)) / 1000.0f;
    }
  return g;
}

// The tests' images are small: windows of 25x25 pixels.
const FlatAreaParams kParams{.area_radius = 12};

TEST(FlatAreas, OneInsideALargeFlatAreaZeroWhereTheGuidesVary) {
  const Image<float> g = half_flat();
  const Image<float> f = flat_areas({g.cview()}, {}, kParams);
  EXPECT_EQ(f(10, 24), 1.0f);  // deep inside the flat half
  EXPECT_EQ(f(80, 24), 0.0f);  // the varying half
  EXPECT_EQ(f(46, 24), 0.0f);  // its patch reaches the varying half
  EXPECT_GT(f(36, 24), 0.0f);  // near the edge: part of its window varies
  EXPECT_LT(f(36, 24), 1.0f);
}

TEST(FlatAreas, EveryGuideMustBeFlat) {
  const Image<float> flat_guide(kW, kH, 2);  // zeros: flat everywhere
  const Image<float> g = half_flat();
  const Image<float> alone = flat_areas({flat_guide.cview()}, {}, kParams);
  EXPECT_EQ(alone(80, 24), 1.0f);
  const Image<float> both = flat_areas({flat_guide.cview(), g.cview()}, {}, kParams);
  EXPECT_EQ(both(80, 24), 0.0f);
  EXPECT_EQ(both(10, 24), 1.0f);
}

TEST(FlatAreas, ASmallFlatAreaIsNotLarge) {
  // A flat 9x9 square in a varying image: its pixels are flat, but their windows are mostly not.
  Image<float> g = half_flat();
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < 48; ++x) g(x, y) = g(x + 48, y);
  for (int y = 20; y < 29; ++y)
    for (int x = 20; x < 29; ++x) g(x, y) = 0.5f;
  const Image<float> f = flat_areas({g.cview()}, {}, kParams);
  EXPECT_EQ(f(24, 24), 0.0f);
}

TEST(FlatAreas, OutsideTheMaskIsNeverFlat) {
  const Image<float> g(kW, kH, 1);  // flat everywhere
  Image<float> mask(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < 24; ++x) mask(x, y) = 1.0f;
  const Image<float> f = flat_areas({g.cview()}, mask.cview(), kParams);
  EXPECT_EQ(f(60, 24), 0.0f);
  EXPECT_EQ(f(5, 24), 1.0f);   // its window is more than 90 % inside
  EXPECT_LT(f(22, 24), 1.0f);  // its window reaches out of the mask
}

}  // namespace
}  // namespace emaki::temporal
