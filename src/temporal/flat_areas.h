// Where a layer's guides are flat over a large area: a wall in shadow, a floor under even light.
// There every patch of the painting with the same guide values fits equally well, so a chain
// with no uniformity term settles each pixel on the same few best-fitting patches and the area
// goes flat (and its tone drifts to theirs), where frame by frame spreads the painting over it.
// Where the guides vary they hold the layout themselves, and the term only adds flicker
// (docs/design/long-shots.md).
#pragma once

#include <vector>

#include "core/image.h"

namespace emaki::temporal {

struct FlatAreaParams {
  int patch_radius = 2;     // a pixel is flat when every guide channel varies by less than
  float tolerance = 0.02f;  // `tolerance` over its (2 patch_radius + 1)^2 patch
  int area_radius = 64;     // the share of flat pixels in a (2 area_radius + 1)^2 window ...
  float share_none = 0.5f;  // ... at or below which the result is 0,
  float share_full = 0.9f;  // ... at or above which it is 1 (linear between)
};

// Per pixel of the guides' size, in [0, 1]: how surely it lies inside a flat area. `guides`: the
// layer's target guide images (values in [0, 1], each any number of channels, all one size);
// `mask`: the layer's mask (1 channel, > 0.5 inside; empty: everything), pixels outside it are
// never flat and count as not flat in their neighbours' windows; a window cut by the image's
// border counts the share of its part inside the image.
Image<float> flat_areas(const std::vector<ImageView<const float>>& guides,
                        ImageView<const float> mask, const FlatAreaParams& params = {});

}  // namespace emaki::temporal
