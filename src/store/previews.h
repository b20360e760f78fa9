// The previews made at the end of a run: the contact sheet and the MP4 (through ffmpeg).
#pragma once

#include <string>
#include <vector>

#include "pipeline/shot_description.h"

namespace emaki::io {

// The contact sheet and the MP4 preview of the composited frames [first, last] (each when the
// shot's outputs ask for it, and only once every frame is composited under the shot's current
// settings). Returns the files written.
std::vector<std::string> write_previews(const pipeline::Shot& shot, int first, int last);

// Encodes `pattern` (printf-style) frames [first, ...] into an H.264 MP4 with the ffmpeg binary.
void encode_mp4(const std::string& pattern, int first, float fps, int crf, const std::string& out);

}  // namespace emaki::io
