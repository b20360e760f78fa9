// `emaki render`: a glTF scene's guide passes, one multilayer EXR per frame.
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <future>
#include <memory>
#include <string>

#include "apps/emaki/commands.h"
#include "apps/emaki/frame_range.h"
#include "apps/emaki/staging_options.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "io/gltf_loader.h"
#include "io/image_io.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::app {
namespace {

namespace fs = std::filesystem;

// The command's own options; the shot around the scene is StagingOptions'.
struct RenderCommandOptions {
  std::string scene_path, frames = "0", out_dir, clip;
  float fps = 24.0f, start_time = 0.0f;
  bool loop = false;
  bool previews = false, full_float = false, quiet = false;
  io::GltfOptions gltf;
  StagingOptions shot{StagingSubject::kScene};
};

void add_options(CLI::App& app, RenderCommandOptions& o) {
  app.add_option("scene", o.scene_path, "the scene, .gltf or .glb")->required();
  app.add_option(
         "--frames", o.frames,
         "frame range A-B (or one frame A), 0 <= A <= B <= 10000000, at most 1000000 frames; "
         "frame f is at clip start + --start + f / fps")
      ->capture_default_str();
  app.add_option("--out", o.out_dir, "output folder (created if missing)")->required();
  app.add_option("--clip", o.clip, "animation clip by name; default: the first clip");
  app.add_flag("--loop", o.loop, "play the clip in a loop, so frames may run past its end");
  app.add_option("--start", o.start_time,
                 "seconds into the clip of frame 0, >= 0 (and within the clip)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--fps", o.fps, "frames per second, [0.01, 1000]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  o.shot.add_to(app);
  app.add_flag("--previews", o.previews,
               "also write DIR/preview/frame_NNNN_<pass>.png for every pass");
  app.add_flag("--float", o.full_float, "32-bit float EXR channels (default: half)");
  app.add_flag("--quiet", o.quiet, "no progress on stderr");
  app.add_flag("--allow-outside-paths", o.gltf.allow_outside_paths,
               "let the scene read buffers and images outside its own folder");
}

scene::ShotSpec resolve_shot(const RenderCommandOptions& o, render::RenderOptions& options) {
  scene::ShotSpec shot;
  o.shot.resolve(shot, options);
  const FrameRange range = parse_frame_range("--frames", o.frames);
  shot.first_frame = range.first;
  shot.last_frame = range.last;
  check_number("--fps", o.fps, render::kMinFps, render::kMaxFps);
  check_number("--start", o.start_time, 0.0f, 1e7f);
  shot.fps = o.fps;
  shot.start_time = o.start_time;
  shot.clip = o.clip;
  shot.loop = o.loop;
  return shot;
}

// One line per frame (rewritten in place on a terminal): frame, count, speed and time left.
class Progress {
 public:
  explicit Progress(int count)
      : count_(count), tty_(isatty(fileno(stderr))), start_(std::chrono::steady_clock::now()) {}
  void frame_done(int frame) {
    ++done_;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double per = elapsed / done_;
    std::fprintf(stderr, "%semaki render: frame %d (%d/%d)  %.2f s/frame  ETA %.0f s%s",
                 tty_ ? "\r" : "", frame, done_, count_, per, per * (count_ - done_),
                 tty_ && done_ < count_ ? "   " : "\n");
    std::fflush(stderr);
  }

 private:
  int count_, done_ = 0;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
};

// Renders every frame of the shot into `dir`.
void render_frames(const RenderCommandOptions& o, const render::ShotRenderer& renderer,
                   const scene::ShotSpec& shot, const fs::path& dir, const fs::path& preview_dir) {
  Progress progress(shot.last_frame - shot.first_frame + 1);
  // A frame's files are written while the next frame renders (compressing an EXR is mostly
  // serial); get() rethrows a write error before anything else is written.
  std::future<void> writing;
  for (int f = shot.first_frame; f <= shot.last_frame; ++f) {
    auto frame = std::make_shared<Image<float>>(renderer.render(f));
    if (render::object_coverage(frame->cview()) == 0.0f)
      throw Error(o.scene_path, fmt::format("frame {}: the camera sees nothing of the scene (all "
                                            "background); check --camera, --target and --fov",
                                            f));
    if (writing.valid()) writing.get();
    const std::string stem = fmt::format("frame_{:04d}", f);
    writing = std::async(std::launch::async, [frame, path = dir / (stem + ".exr"), preview_dir,
                                              stem, half = !o.full_float] {
      write_frame(*frame, path, preview_dir, stem, half);
    });
    if (!o.quiet) progress.frame_done(f);
  }
  if (writing.valid()) writing.get();
}

}  // namespace

int run_render(const Args& args) {
  CLI::App app{
      "Renders the guide passes of a glTF 2.0 scene (.gltf/.glb): one multilayer EXR per frame, "
      "DIR/frame_NNNN.exr, channels as in docs/passes.md.",
      "emaki render"};
  RenderCommandOptions o;
  add_options(app, o);
  if (parse_cli(app, args)) return 0;
  const ScopedThreadCount threads(o.shot.threads);
  render::RenderOptions options;
  const scene::ShotSpec shot = resolve_shot(o, options);

  const scene::Scene scene = io::load_gltf(o.scene_path, o.gltf);
  const render::ShotRenderer renderer(scene, shot, options);
  const fs::path dir(o.out_dir);
  make_output_dir("--out", dir);
  io::check_writable((dir / "frame_0000.exr").string());
  fs::path preview_dir;
  if (o.previews) {
    preview_dir = dir / "preview";
    make_output_dir("--out", preview_dir);
  }
  render_frames(o, renderer, shot, dir, preview_dir);
  if (!o.quiet)
    std::fprintf(stderr, "emaki render: wrote %d frame(s) to %s\n",
                 shot.last_frame - shot.first_frame + 1, dir.string().c_str());
  return 0;
}

}  // namespace emaki::app
