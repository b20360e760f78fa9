// The ink per guide of a layer along its temporal chain (TemporalSpec::ink_ratio): the mean ink
// of the result (one minus its value) over its coverage, divided by the mean ink of one of its
// guide passes over the same pixels (no guide: the mean ink per covered pixel), is measured at
// the chain's first frame; at every temporal frame after it the result's ink is scaled (one
// factor over the frame) so the ratio comes back to that first frame's. The `shadow` and
// `outline` kinds have no temporal guide, so the tone anchor does not reach them and their ink
// walks with the shot's length; frame by frame keeps the mean ink per covered pixel steadier
// than the chain does, not its ratio to a guide's. The shadow, outline and hatching kinds pin it to
// fresh transfers (ink_refresh; docs/design/ink-ratio.md); the guides and bins stay off.
#pragma once

#include <array>
#include <functional>
#include <utility>
#include <vector>

#include "core/image.h"
#include "pipeline/shot_description.h"

namespace emaki::pipeline {

// What a temporal frame's ink is pinned to, measured at the chain's first frame: the ratio of the
// layer's mean ink to its guide's (one entry; TemporalSpec::ink_bins 0), or the layer's mean ink
// at the pixels whose guide ink falls in each of ink_bins equal bins of [0, 1]. Empty where the
// layer or its guide has no ink.
struct InkReference {
  std::vector<double> per_bin;
  // With TemporalSpec::ink_objects: the mean ink per covered pixel of each object (object id,
  // ink) that covers at least ink_object_pixels() of the frame, by id.
  std::vector<std::pair<int, double>> per_object;
  int frame = -1;  // the frame it was measured at, if known
};

// The fewest covered pixels for an object of a width x height frame to have its own reference
// and factor: a thousandth of the frame, at least 32.
long ink_object_pixels(int width, int height);

// With t.ink_refresh > 0, the frame whose fresh transfer sets frame f's reference: the last one
// ink_refresh frames apart from the chain's first frame `first`. Frames are numbered from the
// shot's chain start, not the run's, so a resumed run or a farm chunk measures the same frame.
int ink_reference_frame(const TemporalSpec& t, int first, int f);
// With t.ink_blend: the refresh frame after frame f's reference frame, or -1 when it would be
// after `last` (the shot's last frame) or there is no refresh.
int ink_next_reference_frame(const TemporalSpec& t, int first, int last, int f);
// `a` and `b` blended, s of the way to b (0 <= s <= 1): each entry that both have, by that
// share; one that only one of them has, as it has it.
InkReference blend_ink_references(const InkReference& a, const InkReference& b, double s);

// `value`: value channels, then its coverage (pixels below 0.5 are left out).
InkReference ink_reference(const TemporalSpec& t, ImageView<const float> value, int value_channels,
                           ImageView<const float> passes);

// At the chain's first frame (`chained` false) or with no reference yet (a run resumed inside the
// chain), measures `ref` on `value`; at a temporal frame, scales `value`'s ink inside its
// coverage t.ink_ratio of the way to what `ref` expects from the frame's guide, by one factor
// within [1/2, 2], each value clamped to [0, 1]. With t.ink_confident w > 0 and a `confidence`
// (the temporal guide's), each pixel's ink moves by 1 - w + w x its confidence, the factor set so
// the mean still comes to what `ref` expects: at w = 1 the pixels the chain did not carry
// (uncovered ones) keep their ink. With t.ink_objects (and no ink guide), each object `ref` has
// and the frame covers with at least ink_object_pixels() gets its own factor to its own mean
// ink; the rest of the coverage shares one factor to the layer's mean.
void pin_ink_ratio(const TemporalSpec& t, int value_channels, ImageView<const float> passes,
                   bool chained, InkReference& ref, Image<float>& value,
                   const Image<float>& confidence = {});

// A layer's ink pin along its chain: the reference its frames are pinned to and, with
// TemporalSpec::ink_blend, the two refresh frames' references it is blended from.
class InkPin {
 public:
  // A fresh transfer of the layer at a frame, measured (ink_reference()).
  using Measure = std::function<InkReference(int frame)>;
  // Frame f of a chain from `first` that may run to `last` (the shot's last frame). At the
  // chain's first frame (`chained` false) measures `value`; at a temporal frame sets the frame's
  // reference, measuring the refresh frames it needs (once each) through `measure`, and pins
  // `value` to it (pin_ink_ratio()).
  void pin(const TemporalSpec& t, int first, int last, int f, bool chained, int value_channels,
           ImageView<const float> passes, Image<float>& value, const Image<float>& confidence,
           const Measure& measure);
  const InkReference& reference() const { return ref_; }

 private:
  void refresh(const TemporalSpec& t, int first, int last, int f, const Measure& measure);
  InkReference ref_;
  std::array<InkReference, 2> kept_;  // measured at refresh frames (ink_blend)
};

}  // namespace emaki::pipeline
