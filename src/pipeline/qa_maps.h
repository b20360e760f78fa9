// Per-pixel QA maps: where a layer flickers, where it carries a ghost, where its synthesis found
// no good match in the painting. `emaki qa flicker|ghost --maps` and `emaki run --error-maps`
// write them (store/qa_maps.h) for emaki view's overlay. A map has 2 channels over the frame:
// the measure scaled to [0, 1] (1: the map's scale or more) and whether the pixel was measured
// (1) or not (0), so that a measured pixel with nothing wrong stays apart from one not looked at.
#pragma once

#include "core/image.h"

namespace emaki::pipeline {

// What shows as 1 in each map:
// |B'(t) - B'(t-1)| along the motion vectors (values in [0, 1]; pipeline/flicker.h);
inline constexpr float kFlickerMapScale = 0.25f;
// the temporal guide's pull from another object at a pixel whose surface was hidden at t-1 is a
// share in [0, 1] already (pipeline/ghost.h), shown as it is;
// the synthesis error as a root-mean-square difference per patch pixel, in units of [0, 1]
// values, weighted as the layer's guides and style are (synth/synthesizer.h, "Units").
inline constexpr float kErrorMapScale = 0.75f;

// An empty map of w x h: nothing measured.
Image<float> empty_qa_map(int width, int height);

// The map of a synthesis's per-pixel patch error (synth::Result::error, EbSynth units, for
// patches of `patch_size`) of the layer value `value` (`value_channels` channels, then the
// mask's coverage when masked: pixels outside the mask are not measured).
Image<float> synthesis_error_map(ImageView<const float> error, ImageView<const float> value,
                                 int value_channels, int patch_size);

}  // namespace emaki::pipeline
