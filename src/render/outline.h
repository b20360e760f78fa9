// The outline pass (renderer internals): lines where neighbouring samples differ (silhouettes,
// depth jumps, object / material boundaries, creases), widened by a bounded distance field.
#pragma once

#include "core/image.h"
#include "render/frame_geometry.h"
#include "render/raster.h"
#include "render/renderer.h"

namespace emaki::render::detail {

// Writes the kOutline channel of `frame` from the samples of `vb` (opt.aa per pixel side);
// leaves it 0 when opt.outline_width is 0.
void draw_outline(const VisibilityBuffer& vb, const FrameGeometry& g, const Projector& proj,
                  const RenderOptions& opt, Image<float>& frame);

}  // namespace emaki::render::detail
