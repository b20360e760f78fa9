// emaki qa ghost's measure on a synthetic shot: a dark square (object 2) slides 6 pixels right
// over light ground (object 1); the ground it uncovers was hidden at t-1.
#include "pipeline/ghost.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "render/passes.h"

namespace emaki::pipeline {
namespace {

constexpr int kW = 64, kH = 48, kShift = 6, kX0 = 20, kSide = 16, kY0 = 14;

// The passes of the frame whose square's left edge is at x0 (moved `moved` pixels since t-1).
Image<float> passes(int x0, int moved) {
  Image<float> p(kW, kH, render::kChannelCount);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      float* o = p.at(x, y);
      const bool square = x >= x0 && x < x0 + kSide && y >= kY0 && y < kY0 + kSide;
      o[render::kAlpha] = 1.0f;
      o[render::kObjectId] = square ? 2.0f : 1.0f;
      o[render::kRestPosition] = square ? 0.6f + 0.01f * (x - x0) : float(x) / kW;
      o[render::kRestPosition + 1] = square ? 0.3f + 0.01f * (y - kY0) : 0.0f;
      o[render::kRestPosition + 2] = square ? 0.9f : float(y) / kH;
      o[render::kMotion] = square ? -float(moved) : 0.0f;
    }
  return p;
}

// The touch: the square dark, the ground light.
Image<float> touch(const Image<float>& p) {
  Image<float> v(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) v(x, y) = p(x, y, render::kObjectId) == 2.0f ? 0.1f : 0.9f;
  return v;
}

Layer layer(bool confidence) {
  Layer l;
  l.name = "base";
  l.synth.patch_size = 5;
  l.temporal.confidence = confidence;
  return l;
}

TEST(Ghost, UncoveredGroundIsHiddenAndItsGhostGoesWithConfidence) {
  const Image<float> p0 = passes(kX0, 0), p1 = passes(kX0 + kShift, kShift);
  const Image<float> prev = touch(p0), cur = touch(p1);
  const FrameGhost without =
      frame_ghost(layer(false), cur.cview(), prev.cview(), cur.cview(), p1.cview(), p0.cview(), 1);
  const FrameGhost with =
      frame_ghost(layer(true), cur.cview(), prev.cview(), cur.cview(), p1.cview(), p0.cview(), 1);
  EXPECT_EQ(without.stats.hidden, kShift * kSide);
  EXPECT_EQ(with.stats.hidden, kShift * kSide);
  EXPECT_EQ(without.stats.visible, kW * kH - kShift * kSide);
  EXPECT_EQ(without.stats.diff(), 0.0);  // the reference is the frame itself
  // The strip's values come from ground next to the square at t-1, which the square's patches
  // voted too; with the confidence the temporal guide no longer carries them (the strip's
  // edges keep a little: patches centred beside it still count).
  EXPECT_GT(without.stats.ghost_share(), 0.15);
  EXPECT_LT(with.stats.ghost_share(), 0.25 * without.stats.ghost_share());
}

TEST(Ghost, NeedsATemporalLayer) {
  Layer l = layer(true);
  l.temporal.enabled = false;
  class NoFrames : public FrameSource {
   public:
    Image<float> passes(int) const override { return Image<float>(); }
  } frames;
  class NoStore : public Store {
   public:
    bool has_layer(const Layer&, int) const override { return true; }
    Image<float> read_layer(const Layer&, int) const override { return Image<float>(); }
    void write_layer(const Layer&, int, ImageView<const float>) override {}
    bool has_frame(int) const override { return false; }
    void write_frame(int, ImageView<const float>, const std::vector<ImageView<const float>>&,
                     ImageView<const float>) override {}
  } store;
  EXPECT_THROW(measure_ghost(l, frames, store, 0, 1, nullptr, nullptr), Error);
}

}  // namespace
}  // namespace emaki::pipeline
