// The tone anchor of a layer's temporal guide: B'adv with its low frequencies moved to those of a
// small fresh transfer of the same frame, so the chain cannot drift lighter or darker than the
// painting says the frame should be, while the texture it carries (the high frequencies) stays.
#pragma once

#include <vector>

#include "core/image.h"
#include "synth/synthesizer.h"

namespace emaki::pipeline {

// The exemplar side of the fresh transfer, halved once per layer: `inputs`'s style and source
// guides, in that order.
struct AnchorExemplar {
  int halvings = 0;
  std::vector<Image<float>> planes;
};
AnchorExemplar anchor_exemplar(const synth::Plane& style, const std::vector<synth::Plane>& sources,
                               int halvings);

// `inputs`: the frame's main transfer without its temporal pair; `exemplar`: its exemplar side,
// halved by anchor_exemplar; `params`: the layer's settings
// for a whole-pyramid transfer (its seed included); `advected`: B'adv, value channels first;
// `mask`: the layer's mask at the frame (empty: none). The fresh transfer runs with every input
// halved exemplar.halvings times; the difference of the two, low-passed by `sigma` pixels at that
// size and inside the mask, is added back at full size, times `rate`. Both members are empty when
// the frame or the mask is too small to synthesize at that size; `advected` empty: the field
// alone.
struct Anchor {
  Image<float> target;      // the anchored B'adv (value channels)
  Image<int32_t> nnf;       // the fresh transfer's field scaled to full size ((-1, -1) outside it)
  Image<float> fresh;       // the fresh transfer at its size (value channels), for match_ink()
  Image<float> small_mask;  // the mask at that size (empty: none)
  int halvings = 0;
};
Anchor anchor_tone(const synth::Inputs& inputs, const AnchorExemplar& exemplar,
                   const synth::Params& params, ImageView<const float> advected, int value_channels,
                   const Image<float>& mask, float sigma, float rate = 1.0f);

// The chain's result `layer` (value channels first, values in [0, 1] where 1 is bare paper) with
// its ink, one minus its value, scaled so that the ink's low frequencies (a Gaussian of `sigma`
// pixels at the fresh transfer's size, inside the mask) become the fresh transfer's: the
// strokes the chain carried keep their shape and place, their density follows what the
// painting gives the frame, so a long chain cannot drift lighter or darker. `share` in [0, 1]
// moves that much of the way; the scale is held within [1/2, 2]. Only pixels inside `mask`
// (when not empty) change, each by its `confidence` (when not empty; the temporal guide's: a
// pixel the chain did not carry already started from the painting). Nothing changes when `a`
// has no fresh transfer.
void match_ink(Image<float>& layer, int value_channels, const Anchor& a, const Image<float>& mask,
               const Image<float>& confidence, float sigma, float share);

}  // namespace emaki::pipeline
