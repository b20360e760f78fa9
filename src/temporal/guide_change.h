// Where a layer's own guides changed along the advection: a light that moved, a cast shadow
// that moved on, a silhouette that slid over a surface. B'(t-1) carried there holds the
// painting's answer to the old guides, so the temporal guide should let go and the main transfer
// re-synthesize the pixel from the painting (docs/design/temporal-default.md).
#pragma once

#include "core/image.h"

namespace emaki::temporal {

// For each pixel p of frame t, the largest absolute difference over the channels between
// `current` at p and `previous` at the centre of the patch of t-1 that `nnf` matches p to (the
// advection field). 1 where the field has no match inside t-1. `current`, `previous`: the same
// stacked guide channels of frames t and t-1, values in [0, 1].
Image<float> guide_change(const Image<int32_t>& nnf, ImageView<const float> previous,
                          ImageView<const float> current);

// A Gaussian low-pass of sigma `sigma` pixels per channel (radius 3 sigma, clamped at the
// borders). With `mask` (1 channel, > 0 counts) the weights are restricted to the mask's pixels
// (a normalised convolution, so a thin mask is not washed out by what lies outside it), and
// pixels outside keep their value. sigma <= 0 gives a copy.
Image<float> low_pass(ImageView<const float> image, float sigma, ImageView<const float> mask = {});

}  // namespace emaki::temporal
