// The tone anchor moves B'adv's low frequencies to a fresh transfer's and keeps its fine detail.
#include "pipeline/tone_anchor.h"

#include <gtest/gtest.h>

#include <cmath>

namespace emaki::pipeline {
namespace {

// A ramp along x in [0.1, 0.9]: exemplar and target alike, so a fresh transfer of the style
// (the same ramp) reproduces it.
Image<float> ramp(int w, int h) {
  Image<float> im(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im(x, y) = 0.1f + 0.8f * float(x) / float(w - 1);
  return im;
}

TEST(ToneAnchor, MovesTheToneToTheFreshTransferAndKeepsTheDetail) {
  const Image<float> style = ramp(96, 64), guide = ramp(96, 64), target = ramp(128, 96);
  synth::Inputs in;
  in.style = style.cview();
  in.guides.push_back({"g", guide.cview(), target.cview(), 1.0f});
  synth::Params p;
  p.seed = 7;
  // The carried frame: the ramp, 0.15 lighter, with a fine checker of +-0.05 on it.
  Image<float> carried(128, 96, 1);
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 128; ++x)
      carried(x, y) = target(x, y) + 0.15f + ((x + y) % 2 ? 0.05f : -0.05f);
  const Anchor a = anchor_tone(in, anchor_exemplar(in.style, {in.guides[0].source}, 2), p,
                               carried.cview(), 1, {}, 2.0f);
  ASSERT_EQ(a.target.width(), 128);
  double drift = 0.0, detail = 0.0;
  int count = 0;
  for (int y = 16; y < 80; ++y)
    for (int x = 16; x < 112; ++x) {
      drift += a.target(x, y) - target(x, y);
      detail += std::abs(a.target(x, y) - a.target(x + 1, y));
      ++count;
    }
  drift /= count, detail /= count;
  EXPECT_LT(std::abs(drift), 0.04) << "the carried frame was 0.15 lighter";
  EXPECT_GT(detail, 0.08) << "the checker (0.1 between neighbours) was smoothed away";
  // The field: every entry inside the exemplar, near the source column that the ramp matches.
  ASSERT_EQ(a.nnf.width(), 128);
  double off = 0.0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 128; ++x) {
      ASSERT_GE(a.nnf(x, y, 0), 0);
      ASSERT_LT(a.nnf(x, y, 0), 96);
      ASSERT_GE(a.nnf(x, y, 1), 0);
      ASSERT_LT(a.nnf(x, y, 1), 64);
      off += std::abs(a.nnf(x, y, 0) - x * 95.0 / 127.0);
    }
  EXPECT_LT(off / (128 * 96), 8.0);
}

TEST(ToneAnchor, IsTheSameForTheSameInputs) {
  const Image<float> style = ramp(64, 48), target = ramp(80, 60);
  synth::Inputs in;
  in.style = style.cview();
  in.guides.push_back({"g", style.cview(), target.cview(), 1.0f});
  synth::Params p;
  const AnchorExemplar e = anchor_exemplar(in.style, {in.guides[0].source}, 1);
  const Anchor a = anchor_tone(in, e, p, target.cview(), 1, {}, 2.0f);
  const Anchor b = anchor_tone(in, e, p, target.cview(), 1, {}, 2.0f);
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      ASSERT_EQ(a.target(x, y), b.target(x, y));
      ASSERT_EQ(a.nnf(x, y, 0), b.nnf(x, y, 0));
    }
}

// Strokes of ink 0.4 (value 0.6) on bare paper, every fourth column; the fresh transfer at half
// size says the frame holds twice that ink. Away from the borders (where the halving clamps):
TEST(MatchInk, ScalesTheInkToTheFreshTransfersAndKeepsTheStrokesShape) {
  const int w = 64, h = 32;
  Image<float> layer(w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      layer(x, y, 0) = x % 4 == 0 ? 0.6f : 1.0f;
      layer(x, y, 1) = 1.0f;  // coverage: untouched
    }
  // The layer's ink is 0.1 a pixel: the fresh transfer holds 0.2.
  Anchor a;
  a.halvings = 1;
  a.fresh.reset(w / 2, h / 2, 1);
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w / 2; ++x) a.fresh(x, y) = 0.8f;
  const Image<float> before = layer.clone();
  Image<float> probe = layer.clone();
  match_ink(probe, 1, a, {}, {}, 2.0f, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) ASSERT_EQ(probe(x, y, 0), before(x, y, 0)) << "share 0";
  Image<float> half = layer.clone();
  match_ink(layer, 1, a, {}, {}, 2.0f, 1.0f);
  match_ink(half, 1, a, {}, {}, 2.0f, 0.5f);
  // (0.2 + floor) / (0.1 + floor) with the floor 0.02: 1.83 times the ink; half the way, 1.42.
  const double full_scale = 0.22 / 0.12, half_scale = 1.0 + (full_scale - 1.0) / 2.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      EXPECT_EQ(layer(x, y, 1), 1.0f);
      if (x % 4 != 0) {
        ASSERT_EQ(layer(x, y, 0), 1.0f) << "bare paper stays bare at " << x << "," << y;
      } else if (x >= 16 && x < 48 && y >= 8 && y < 24) {
        EXPECT_NEAR(1.0 - layer(x, y, 0), 0.4 * full_scale, 0.02) << x << "," << y;
        EXPECT_NEAR(1.0 - half(x, y, 0), 0.4 * half_scale, 0.02) << x << "," << y;
      }
    }
}

TEST(MatchInk, ChangesNothingOutsideTheMaskOrWithoutAFreshTransfer) {
  Image<float> layer(16, 16, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) layer(x, y) = (x + y) % 3 ? 0.9f : 0.5f;
  const Image<float> before = layer.clone();
  match_ink(layer, 1, Anchor{}, {}, {}, 2.0f, 1.0f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) ASSERT_EQ(layer(x, y), before(x, y));
  Anchor a;
  a.halvings = 1;
  a.fresh.reset(8, 8, 1);  // all ink: the scale is held at 2
  Image<float> mask(16, 16, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) mask(x, y) = x < 8 ? 1.0f : 0.0f;
  // No confidence on the first row: a pixel the chain did not carry is left as it is.
  Image<float> confidence(16, 16, 1);
  for (int y = 1; y < 16; ++y)
    for (int x = 0; x < 16; ++x) confidence(x, y) = 1.0f;
  match_ink(layer, 1, a, mask, confidence, 2.0f, 1.0f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      if (x >= 8 || y == 0) {
        ASSERT_EQ(layer(x, y), before(x, y))
            << "outside the mask or not carried at " << x << "," << y;
      } else {
        EXPECT_NEAR(1.0f - layer(x, y), 2.0f * (1.0f - before(x, y)), 1e-5f);
      }
    }
}

}  // namespace
}  // namespace emaki::pipeline
