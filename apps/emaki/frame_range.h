// The command line's one frame-range parser (`--frames` of render, run, composite and qa).
#pragma once

#include <string>

namespace emaki::app {

struct FrameRange {
  int first = 0, last = 0;  // inclusive
};

// "FIRST-LAST" or "FRAME", with 0 <= FIRST <= LAST <= kMaxFrame and at most kMaxFrameCount
// frames (core/limits.h). Digits only, parsed as 64-bit and checked, so no value wraps into range
// and no frame arithmetic downstream can overflow. Throws emaki::Error naming `option`.
FrameRange parse_frame_range(const std::string& option, const std::string& text);

}  // namespace emaki::app
