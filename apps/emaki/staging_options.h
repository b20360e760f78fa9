// Command-line options shared by `emaki render` and `emaki template`: the renderer settings and
// the shot around the subject (camera, light, ground, background), bound to a CLI11 app.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "exemplar/reference_sphere.h"
#include "render/renderer.h"
#include "scene/staging.h"

namespace emaki::app {

// What the options frame. The subject decides which options there are, their defaults and their
// bounds (staging_options.cpp lists them side by side).
enum class StagingSubject {
  kScene,            // `emaki render`: a glTF scene; every option, camera motion included
  kReferenceSphere,  // `emaki template`: the reference sphere; exemplar::reference_shot aims
                     // the camera, so --elevation and --fov are its only camera options
};

// Raw option values as typed; resolve() checks them and fills the specs.
struct StagingOptions {
  explicit StagingOptions(StagingSubject subject);

  StagingSubject subject;
  // size, aa, elevation and fov default by subject; options a subject lacks keep these values.
  std::string size;
  int aa;
  float outline_width = 1.5f;
  float crease_deg = 45.0f;
  std::string camera, target, pan;
  float azimuth = 30.0f, elevation, distance = 0.0f, fov;
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

  // Adds the subject's options, with their current values as defaults.
  void add_to(CLI::App& app);
  // kScene: the shot and the renderer settings.
  void resolve(scene::ShotSpec& shot, render::RenderOptions& options) const;
  // kReferenceSphere: everything but the size, which --fit takes from the painting instead of
  // --size (parse_size(size) otherwise); `options` takes the size from `spec` after that.
  void resolve(exemplar::ReferenceSpec& spec, render::RenderOptions& options) const;

 private:
  void add_motion_options(CLI::App& app);            // --orbit --dolly --pan --gltf-camera
  void add_ground_placement_options(CLI::App& app);  // --ground-size --ground-height
  // Both subjects: every option but --size.
  void resolve_shot(scene::ShotSpec& shot, render::RenderOptions& options) const;
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
// Parses "WxH": each side in [1, 16384], the area within the pixel budget (--max-pixels).
void parse_size(const std::string& option, const std::string& text, int& width, int& height);

// Creates `dir` and its parents; throws emaki::Error naming `option` when it cannot.
void make_output_dir(const std::string& option, const std::filesystem::path& dir);

// Writes one frame's multilayer EXR (atomically; half or float channels) and, when preview_dir
// is not empty, a PNG per pass named <stem>_<pass>.png there.
void write_frame(const Image<float>& frame, const std::filesystem::path& exr,
                 const std::filesystem::path& preview_dir, const std::string& stem, bool half);

// Runs CLI11 on `args`; returns true when --help was printed (the command then returns 0).
// A parse error becomes an emaki::Error with CLI11's message, which names the option.
bool parse_cli(CLI::App& app, const Args& args);

}  // namespace emaki::app
