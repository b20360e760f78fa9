// Where a shot's guide passes come from, and what the pipeline derives from them: one pass cut
// out of a frame, a layer's synthesis mask, a MatCap-like exemplar's reference passes.
// Every frame is an interleaved float image in the layout of render/passes.h.
#pragma once

#include <memory>
#include <string>

#include "core/image.h"
#include "pipeline/shot_description.h"
#include "scene/scene.h"

namespace emaki::pipeline {

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The kChannelCount-channel passes of `frame`.
  virtual Image<float> passes(int frame) const = 0;
};

// Renders the frames of a glTF scene with emaki's renderer.
std::unique_ptr<FrameSource> scene_frames(scene::Scene scene, const Source& source);

// Channels [first, first + count) of a frame, as their own image.
Image<float> extract(ImageView<const float> passes, int first, int count);
// The pass called `name` (passes.h) of a frame.
Image<float> extract_pass(ImageView<const float> passes, const std::string& name);

// A layer's target mask (1 channel, 1 inside, 0 outside), or an empty image for MaskKind::kNone.
Image<float> layer_mask(ImageView<const float> passes, const MaskSpec& mask);

// The reference sphere's passes fitted to a MatCap-like exemplar's painting of size w x h.
Image<float> matcap_passes(const Exemplar& exemplar, int width, int height);

// The advection guide of a frame: normalised world position (3 channels) or rest position plus
// object id (4 channels).
Image<float> advection_guide(ImageView<const float> passes, AdvectionGuide guide);

}  // namespace emaki::pipeline
