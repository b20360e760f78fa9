// The guide passes: their order in a frame's interleaved float image and their EXR channel
// names (docs/passes.md is the user-facing table; the Blender exporter writes the same names).
#pragma once

#include <string>
#include <vector>

#include "core/image.h"

namespace emaki::render {

// First channel of each pass in the interleaved frame image.
enum Channel : int {
  kNormal = 0,        // 3: camera space, x right, y up, z towards the viewer
  kPosition = 3,      // 3: world space
  kPositionNorm = 6,  // 3: world space mapped into the shot's fixed box -> [0, 1]
  kRestPosition = 9,  // 3: rest-pose object space mapped into the scene's rest box -> [0, 1]
  kDepth = 12,        // 1: view-space distance along the camera axis
  kDiffuse = 13,      // 1: max(0, N.L) x light visibility
  kShadow = 14,       // 1: cast-shadow mask of the key light
  kAlbedo = 15,       // 3: linear base colour x texture
  kObjectId = 18,     // 1: 0 background, 1 ground, 2.. scene objects
  kMaterialId = 19,   // 1: 0 background, 1 ground, 2.. scene materials
  kOutline = 20,      // 1: line coverage
  kMotion = 21,       // 2: pixels from here to the same surface point in the previous frame
  kAlpha = 23,        // 1: coverage
  kChannelCount = 24,
};

struct PassInfo {
  const char* name;
  int first;
  int count;
  const char* suffixes;  // one letter per channel
};

// All passes in channel order.
const std::vector<PassInfo>& pass_table();
// The EXR channel names in channel order ("normal.X", ..., "alpha.A").
std::vector<std::string> channel_names();
// The pass called `name`, or nullptr.
const PassInfo* find_pass(const std::string& name);

// A viewable RGB rendition of one pass for previews and contact sheets (display-referred,
// sRGB-encoded [0, 1]): normals as 0.5 + 0.5 n, depth normalised over the frame, ids as
// distinct colours, motion as hue/saturation, outline black on white.
Image<float> preview(ImageView<const float> frame, const PassInfo& pass);

}  // namespace emaki::render
