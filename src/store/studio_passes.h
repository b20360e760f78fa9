// Studio renders into emaki's passes: the channel presets of a `sequence` source and the
// conversion of a plain Blender (Cycles) multilayer EXR into emaki's pass definitions
// (docs/passes.md). The conversions work on images in memory; shot_inputs.cpp reads the files.
//
// Blender's conventions, and what the `blender` preset does with them:
//   - Every data pass is averaged over all samples of a pixel, background samples counting as
//     zero: values are premultiplied by the coverage. They are divided by Combined.A.
//   - World space is Z-up; emaki's (glTF's) is +Y up: (x, y, z)_blender -> (x, z, -y).
//   - Normal is world-space; emaki's is camera-space. No camera is stored in the file, so the
//     camera's orientation is recovered per frame from Position and the pixel grid (a linear
//     camera fit, DLT) and the normals turned into it.
//   - Vector.XY points from here to where the surface was in the previous frame, in pixels,
//     x right, y up (measured against emaki's renderer); emaki's y points down: (X, -Y).
//   - Depth.Z is the distance along the camera axis, 1e10 on the background; emaki's is 0 there.
//   - DiffDir (mean of RGB) divided by the key light's strength (fitted, see shadow) is the
//     diffuse pass (light without colour); DiffCol the albedo; IndexOB / IndexMA the ids, where a
//     covered pixel with index 0 (Blender's default) counts as 2 (an object), 1 is the ground.
//   - Passes a plain render does not have are derived: position_norm (the cube around the
//     shot's covered non-ground positions), rest_position (= position_norm), shadow (the key
//     light's direction fitted to DiffDir = N.L; shadow = 1 - DiffDir / N.L where lit-facing),
//     outline (id changes, depth jumps over 3 %, creases over 45 degrees, one pixel each side).
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "core/image.h"

namespace emaki::io {

// The channels of a plain Blender render that the `blender` preset reads, in this order.
std::vector<std::string> blender_channels(const std::string& view_layer);
inline constexpr int kBlenderChannelCount = 18;

// emaki's normalisation cube: corner and side (uniform scale).
struct Cube {
  glm::vec3 lo{-1.0f};
  float side = 2.0f;
};

// Grows `lo`/`hi` by the covered, non-ground positions (+Y up) of a raw Blender frame.
void add_blender_bounds(ImageView<const float> raw, glm::vec3& lo, glm::vec3& hi);
Cube cube_around(const glm::vec3& lo, const glm::vec3& hi);

// Camera axes recovered from world points and their pixel positions: x right, y up, z towards
// the viewer (emaki's camera space), as rows. Throws emaki::Error naming `file` when the points
// do not determine a camera (too few, or all on one plane).
struct CameraAxes {
  glm::vec3 right, up, back;
};
CameraAxes fit_camera_axes(const std::vector<glm::vec3>& world, const std::vector<glm::vec2>& pixel,
                           const std::string& file);

// A raw Blender frame (blender_channels order) as emaki's kChannelCount-channel frame.
Image<float> blender_to_emaki(ImageView<const float> raw, const Cube& position_cube,
                              const std::string& file);

// Another renderer's AOVs, read under emaki's names (source.channels), in its conventions.
struct AovConventions {
  bool world_normals = false;  // normal in world space: turned into the camera's (fitted) space
  bool z_up = false;           // position and world normals Z-up: (x, y, z) -> (x, z, -y)
  bool premultiplied = false;  // continuous passes divided by alpha
};

// Brings a frame read under emaki's channel order to emaki's conventions, in place.
void apply_conventions(Image<float>& frame, const AovConventions& c, const std::string& file);

}  // namespace emaki::io
