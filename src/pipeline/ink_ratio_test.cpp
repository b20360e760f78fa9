// The ink per guide: measured at the chain's first frame, pinned at the frames after it.
#include "pipeline/ink_ratio.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace emaki::pipeline
