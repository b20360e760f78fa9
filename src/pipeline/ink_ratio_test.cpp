// The ink per guide: measured at the chain's first frame, pinned at the frames after it.
#include "pipeline/ink_ratio.h"

#include <gtest/gtest.h>

#include <vector>

#include "render/passes.h"

namespace emaki::pipeline {
namespace {

// A layer frame: `value` over the left half (its coverage), transparent elsewhere.
Image<float> half_covered(float value) {
  Image<float> im(16, 8, 2);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) im(x, y, 0) = x < 8 ? value : 0.0f, im(x, y, 1) = x < 8;
  return im;
}

TEST(InkRatio, PinsTheFirstFramesInkInsideTheCoverage) {
  TemporalSpec t;
  t.ink_ratio = 1.0f;  // no guide: the mean ink over the coverage
  InkReference ref;
  Image<float> first = half_covered(0.6f);
  pin_ink_ratio(t, 1, {}, false, ref, first);  // measures, changes nothing
  ASSERT_EQ(ref.per_bin.size(), 1u);
  EXPECT_NEAR(ref.per_bin[0], 0.4, 1e-6);
  EXPECT_FLOAT_EQ(first(3, 3, 0), 0.6f);
  Image<float> later = half_covered(0.8f);  // half the ink
  pin_ink_ratio(t, 1, {}, true, ref, later);
  EXPECT_NEAR(later(3, 3, 0), 0.6f, 1e-6);
  EXPECT_FLOAT_EQ(later(12, 3, 0), 0.0f);  // outside the coverage: untouched
  t.ink_ratio = 0.5f;                      // half of the way
  Image<float> half = half_covered(0.8f);
  pin_ink_ratio(t, 1, {}, true, ref, half);
  EXPECT_NEAR(half(3, 3, 0), 0.7f, 1e-6);
}

TEST(InkRatio, LeavesThePixelsTheChainDidNotCarryWithTheConfidence) {
  TemporalSpec t;
  t.ink_ratio = 1.0f;
  t.ink_confident = 1.0f;
  InkReference ref;
  Image<float> first = half_covered(0.6f);
  pin_ink_ratio(t, 1, {}, false, ref, first);
  // Three quarters of the ink; the confidence is 0 over the covered columns 0-3, 1 over 4-7.
  Image<float> later = half_covered(0.7f), confidence(16, 8, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) confidence(x, y) = x >= 4;
  pin_ink_ratio(t, 1, {}, true, ref, later, confidence);
  EXPECT_FLOAT_EQ(later(1, 3, 0), 0.7f);  // uncovered: its ink stays
  // The carried pixels take the whole difference: the mean ink comes back to 0.4.
  EXPECT_NEAR(later(5, 3, 0), 0.5f, 1e-6);
  // Half weighted: the uncovered pixels take half the factor's move, the carried ones all of it,
  // and the mean still comes back (inks 0.3 -> 0.3667 and 0.4333).
  t.ink_confident = 0.5f;
  Image<float> half = half_covered(0.7f);
  pin_ink_ratio(t, 1, {}, true, ref, half, confidence);
  EXPECT_NEAR(half(1, 3, 0), 1.0f - 0.3f * (1.0f + 0.5f * 4.0f / 9.0f), 1e-5);
  EXPECT_NEAR(half(5, 3, 0), 1.0f - 0.3f * (1.0f + 4.0f / 9.0f), 1e-5);
}

TEST(InkRatio, RefreshFramesCountFromTheChainsFirstFrame) {
  TemporalSpec t;
  EXPECT_EQ(ink_reference_frame(t, 10, 25), 10);  // no refresh: the first frame's alone
  t.ink_refresh = 8;
  EXPECT_EQ(ink_reference_frame(t, 10, 10), 10);
  EXPECT_EQ(ink_reference_frame(t, 10, 17), 10);
  EXPECT_EQ(ink_reference_frame(t, 10, 18), 18);
  EXPECT_EQ(ink_reference_frame(t, 10, 33), 26);
}

// Passes of a 64x8 frame showing object 2 over columns 0-31, object 3 over 32-60 and object 4
// over 61-63 (24 pixels: fewer than ink_object_pixels()'s 32).
Image<float> three_objects() {
  Image<float> p(64, 8, render::kChannelCount);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 64; ++x)
      p(x, y, render::kAlpha) = 1.0f, p(x, y, render::kObjectId) = x < 32 ? 2.0f : x < 61 ? 3 : 4;
  return p;
}

// Covered everywhere: `left` over columns 0-31, `right` over 32-63.
Image<float> two_values(float left, float right) {
  Image<float> im(64, 8, 2);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 64; ++x) im(x, y, 0) = x < 32 ? left : right, im(x, y, 1) = 1.0f;
  return im;
}

TEST(InkRatio, EachObjectLargeEnoughKeepsItsOwnInk) {
  TemporalSpec t;
  t.ink_ratio = 1.0f;
  t.ink_objects = true;
  const Image<float> passes = three_objects();
  InkReference ref;
  Image<float> first = two_values(0.6f, 0.8f);  // inks 0.4 and 0.2
  pin_ink_ratio(t, 1, passes.cview(), false, ref, first);
  ASSERT_EQ(ref.per_object.size(), 2u);  // object 4 is too small for its own
  EXPECT_EQ(ref.per_object[0].first, 2);
  EXPECT_NEAR(ref.per_object[0].second, 0.4, 1e-6);
  EXPECT_NEAR(ref.per_object[1].second, 0.2, 1e-6);
  // Object 2 lost half its ink, object 3 kept its (both cover more than 4 x 32 pixels: their own
  // factors in full): only object 2 is moved, back to 0.4. Object 4 (ink 0.2) has none, and
  // too few pixels for a factor of its own group: it takes the frame's, to the mean ink 0.3.
  Image<float> later = two_values(0.8f, 0.8f);
  pin_ink_ratio(t, 1, passes.cview(), true, ref, later);
  EXPECT_NEAR(later(3, 3, 0), 0.6f, 1e-6);
  EXPECT_NEAR(later(40, 3, 0), 0.8f, 1e-6);
  EXPECT_NEAR(later(62, 3, 0), 0.7f, 1e-6);
  // One factor over the frame without ink_objects: the mean ink 0.2 goes back to 0.3.
  t.ink_objects = false;
  InkReference whole;
  Image<float> again = two_values(0.6f, 0.8f);
  pin_ink_ratio(t, 1, passes.cview(), false, whole, again);
  Image<float> flat = two_values(0.8f, 0.8f);
  pin_ink_ratio(t, 1, passes.cview(), true, whole, flat);
  EXPECT_NEAR(flat(3, 3, 0), 0.7f, 1e-6);
  EXPECT_NEAR(flat(40, 3, 0), 0.7f, 1e-6);
}

// TemporalSpec::ink_blend: each frame's reference is its two refresh frames' blended by its
// distance to them, each refresh frame measured once; past the last refresh frame before the
// shot's end, that frame's alone.
TEST(InkRatio, BlendedReferencesMoveFromOneRefreshToTheNext) {
  TemporalSpec t;
  t.ink_ratio = 1.0f;
  t.ink_refresh = 4;
  t.ink_blend = true;
  std::vector<int> measured;
  const InkPin::Measure measure = [&](int k) {
    measured.push_back(k);
    InkReference r;
    r.per_bin = {0.4 + 0.05 * k};
    r.frame = k;
    return r;
  };
  InkPin pin;
  Image<float> first = half_covered(0.6f);  // ink 0.4: frame 0's reference, not measured again
  pin.pin(t, 0, 10, 0, false, 1, {}, first, {}, measure);
  const float want[11] = {0.4f, 0.45f, 0.5f, 0.55f, 0.6f, 0.65f,
                          0.7f, 0.75f, 0.8f, 0.8f,  0.8f};  // frames 8-10: frame 8's
  for (int f = 1; f <= 10; ++f) {
    Image<float> v = half_covered(0.5f);  // ink 0.5: every factor within [1/2, 2]
    pin.pin(t, 0, 10, f, true, 1, {}, v, {}, measure);
    EXPECT_NEAR(1.0f - v(3, 3, 0), want[f], 1e-5) << f;
  }
  EXPECT_EQ(measured, (std::vector<int>{4, 8}));
  // Entries only one side has are kept as they are.
  InkReference a, b;
  a.per_bin = {0.2}, b.per_bin = {0.4};
  a.per_object = {{2, 0.1}, {3, 0.3}}, b.per_object = {{3, 0.5}, {4, 0.7}};
  const InkReference m = blend_ink_references(a, b, 0.25);
  EXPECT_NEAR(m.per_bin[0], 0.25, 1e-12);
  ASSERT_EQ(m.per_object.size(), 3u);
  EXPECT_NEAR(m.per_object[0].second, 0.1, 1e-12);
  EXPECT_NEAR(m.per_object[1].second, 0.35, 1e-12);
  EXPECT_NEAR(m.per_object[2].second, 0.7, 1e-12);
}

}  // namespace
}  // namespace emaki::pipeline
