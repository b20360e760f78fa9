// Area resampling: each output pixel is the mean of the input area it covers (a box filter of
// the output's footprint, partial pixels weighted by their covered fraction). For shrinking a
// painting to a preview's scale (emaki lookdev --scale): it keeps the mean tone exactly and
// aliases nothing a shrink by a whole factor would not.
#pragma once

#include "core/image.h"

namespace emaki {

// `in` resampled to width x height (each >= 1), any channel count.
Image<float> resample_area(ImageView<const float> in, int width, int height);

}  // namespace emaki
