// The carried field made locally coherent again. A warm start carries each pixel's exemplar patch
// along the surface's motion; where the surface turns or shears on screen (an orbiting camera
// over a ground plane), neighbouring pixels keep their patches but not their patches' relative
// offsets, so the overlapping patches no longer agree and the vote blurs them: frame after frame
// the chain loses the painting's grain. Snapping each pixel's offset (its patch centre minus its
// own position) to the most common offset around it puts the patches back side by side, as the
// painting has them, while the pieces' positions still follow the surface
// (docs/design/long-shots.md#the-grain-under-a-turning-camera).
#pragma once

#include <cstdint>

#include "core/image.h"

namespace emaki::temporal {

// `field`: 2 channels, each pixel's exemplar patch centre (x, y); a negative x marks a pixel with
// none, which stays as it is and does not count in its neighbours' windows. Each other pixel
// takes the offset that the most pixels of its (2 radius + 1)^2 window (cut by the image's
// border) have, when more pixels have it than have its own; ties go to its own offset, then to
// the offset met first in row order. The new centre may leave the exemplar: the synthesizer
// draws such entries afresh (synth::Params::initial_nnf). radius <= 0: the field unchanged.
// Deterministic, whatever the thread count.
Image<int32_t> coherent_field(ImageView<const int32_t> field, int radius);

}  // namespace emaki::temporal
