// Where a shot's guide passes come from, and what the pipeline derives from them: one pass cut
// out of a frame, a layer's synthesis mask, a MatCap-like exemplar's reference passes.
// Every frame is an interleaved float image in the layout of render/passes.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "pipeline/shot_description.h"
#include "scene/scene.h"
#include "temporal/advection.h"

namespace emaki::pipeline {

// An advection field made before the synthesis (the farm's passes task keeps each frame's in the
// pass cache): the field of the layers that advect with `guide`, `patch_size` and `seed`
// (frame_seed(layer, frame, 1), pipeline/temporal_guide.h) at one frame.
struct KeptField {
  AdvectionGuide guide = AdvectionGuide::kRestPosition;
  int patch_size = 0;
  uint64_t seed = 0;
  temporal::AdvectionField field;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // The kChannelCount-channel passes of `frame`.
  virtual Image<float> passes(int frame) const = 0;
  // The advection fields kept for `frame`; any other field is computed where it is needed.
  virtual std::vector<KeptField> kept_fields(int /*frame*/) const { return {}; }
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
