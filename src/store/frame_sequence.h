// A studio render as the shot's frames: one multilayer EXR per frame, named by a printf-style
// pattern, its channels read by the source's preset and mapping (store/studio_passes.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pipeline/frames.h"
#include "pipeline/shot_description.h"
#include "render/passes.h"

namespace emaki::io {

// The widest frame number a pattern may ask for (%012d): wider is refused, never padded.
inline constexpr int kMaxFrameWidth = 12;

// The file of frame `frame` of a printf-style pattern ("frame_%04d.exr"); the pattern holds %d
// or %0Nd only (the shot file checks it), and a width over kMaxFrameWidth throws (field
// "sequence").
std::string frame_file(const std::string& pattern, int frame);

// The channel names a sequence source reads for `pass` (its mapping, or emaki's own names).
std::vector<std::string> source_channels(const pipeline::Source& source,
                                         const render::PassInfo& pass);

// One pass file as emaki's frame (render::kChannelCount channels): preset kEmaki reads emaki's
// channel names (a single-channel pass also as NAME.V, as the Blender exporter writes it);
// kBlender converts a plain Blender render of view layer `view_layer`, position_norm's cube
// taken from this frame alone.
Image<float> read_pass_file(const std::string& file,
                            pipeline::SourcePreset preset = pipeline::SourcePreset::kEmaki,
                            const std::string& view_layer = "ViewLayer");

// The frames of a sequence source; every frame must have the first frame's size.
std::unique_ptr<pipeline::FrameSource> open_sequence(const pipeline::Source& source);

}  // namespace emaki::io
