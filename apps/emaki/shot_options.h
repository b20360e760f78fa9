// Command-line options shared by `emaki render` and `emaki template`: the shot description
// (camera, light, ground, background) and the renderer settings, bound to a CLI11 app.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "render/renderer.h"
#include "scene/shot.h"

namespace emaki::app {

// Raw option values as typed; resolve() checks them and fills a ShotSpec / RenderOptions.
struct ShotOptions {
  std::string size = "640x360";
  int aa = 2;
  float outline_width = 1.5f;
  float crease_deg = 45.0f;
  std::string camera, target, pan;
  float azimuth = 30.0f, elevation = 15.0f, distance = 0.0f, fov = 40.0f;
  float ortho = 0.0f, orbit = 0.0f, dolly = 1.0f;
  int gltf_camera = -1;
  std::string light = "-1,1,1";
  bool light_world = false;
  float softness = 2.0f;
  bool no_ground = false;
  float ground_size = 0.0f;
  std::string ground_height;
  std::string ground_color = "0.8,0.8,0.8";
  std::string background = "0,0,0";
  int threads = 0;

  // Adds the options; `with_motion` adds --orbit / --dolly / --pan / --gltf-camera.
  void add_to(CLI::App& app, bool with_motion);
  void resolve(scene::ShotSpec& shot, render::RenderOptions& options) const;
};

// Scene units, pixels, degrees and seconds an option may give: at most this in magnitude (as in
// a shot file), so that squares stay within a float.
inline constexpr float kMaxOptionMagnitude = 1e9f;

// Throws emaki::Error naming `option` unless `value` is finite and within [lo, hi]. CLI11's
// own range checks let nan through (every comparison with it is false) and accept inf.
void check_number(const std::string& option, float value, float lo = -kMaxOptionMagnitude,
                  float hi = kMaxOptionMagnitude);

// Parses "X,Y,Z"-style lists (finite, within +-kMaxOptionMagnitude); throws emaki::Error naming
// `option`.
std::vector<float> parse_floats(const std::string& option, const std::string& text, int count);
// Parses "WxH".
void parse_size(const std::string& option, const std::string& text, int& width, int& height);

// Writes one frame's multilayer EXR (atomically; half or float channels) and, when preview_dir
// is not empty, a PNG per pass named <stem>_<pass>.png there.
void write_frame(const Image<float>& frame, const std::filesystem::path& exr,
                 const std::filesystem::path& preview_dir, const std::string& stem, bool half);

// Runs CLI11 on `args`; returns true when --help was printed (the command then returns 0).
// Parse errors become emaki::Error naming the option.
bool parse_cli(CLI::App& app, const Args& args);

}  // namespace emaki::app
