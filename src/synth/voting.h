// Voting: each target pixel becomes the (weighted) average of the source pixels that the
// overlapping target patches map onto it.
#pragma once

#include "core/image.h"
#include "synth/synthesizer.h"

namespace emaki::synth {

// source: the style exemplar at this level (integer samples mean [0, 1]).
// nnf: tw x th x 2 source patch centres; err: patch errors (used by kWeighted); active: tw x th
// or empty. Writes `out` (tw x th x source channels); inactive pixels get 0.
void vote(const Plane& source, const Image<int32_t>& nnf, const Image<float>& err,
          const Image<uint8_t>& active, int patch_size, VoteMode mode, Image<float>& out);

// Where a masked synthesis works (`active` above): the non-zero pixels of `inside` dilated by
// `radius` in x and y (a square), so that pixels at the mask's edge get whole patches.
Image<uint8_t> dilate_mask(const Image<uint8_t>& inside, int radius);

}  // namespace emaki::synth
