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
#include "apps/emaki/shot_options.h"
#include "core/error.h"
#include "core/limits.h"
#include "io/gltf_loader.h"
#include "io/image_io.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::app {
namespace {

namespace fs = std::filesystem;

void make_dir(const std::string& option, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw Error(option, fmt::format("cannot create folder '{}'", dir.string()));
}

}  // namespace

// Writes one frame's EXR (atomically) and, if asked, a PNG per pass.
void write_frame(const Image<float>& frame, const fs::path& exr, const fs::path& preview_dir,
                 const std::string& stem, bool half) {
  io::WriteOptions wo;
  wo.format = half ? io::SampleFormat::kHalf : io::SampleFormat::kFloat;
  wo.channel_names = render::channel_names();
  io::write_image(exr.string(), frame.cview(), wo);
  if (preview_dir.empty()) return;
  for (const render::PassInfo& pass : render::pass_table()) {
    const Image<float> p = render::preview(frame.cview(), pass);
    io::WriteOptions po;
    po.format = io::SampleFormat::kU8;
    io::write_image((preview_dir / fmt::format("{}_{}.png", stem, pass.name)).string(), p.cview(),
                    po);
  }
}

int run_render(const Args& args) {
  CLI::App app{
      "Renders the guide passes of a glTF 2.0 scene (.gltf/.glb): one multilayer EXR per frame, "
      "DIR/frame_NNNN.exr, channels as in docs/passes.md.",
      "emaki render"};
  std::string scene_path, frames = "0", out_dir, clip;
  float fps = 24.0f, start_time = 0.0f;
  bool loop = false;
  bool previews = false, full_float = false, quiet = false;
  ShotOptions so;
  app.add_option("scene", scene_path, "the scene, .gltf or .glb")->required();
  app.add_option(
         "--frames", frames,
         "frame range A-B (or one frame A), 0 <= A <= B <= 10000000, at most 1000000 frames; "
         "frame f is at clip start + --start + f / fps")
      ->capture_default_str();
  app.add_option("--out", out_dir, "output folder (created if missing)")->required();
  app.add_option("--clip", clip, "animation clip by name; default: the first clip");
  app.add_flag("--loop", loop, "play the clip in a loop, so frames may run past its end");
  app.add_option("--start", start_time,
                 "seconds into the clip of frame 0, >= 0 (and within the clip)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--fps", fps, "frames per second, [0.01, 1000]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  so.add_to(app, true);
  app.add_flag("--previews", previews,
               "also write DIR/preview/frame_NNNN_<pass>.png for every pass");
  app.add_flag("--float", full_float, "32-bit float EXR channels (default: half)");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  io::GltfOptions gltf_options;
  app.add_flag("--allow-outside-paths", gltf_options.allow_outside_paths,
               "let the scene read buffers and images outside its own folder");
  if (parse_cli(app, args)) return 0;

  scene::ShotSpec shot;
  render::RenderOptions options;
  so.resolve(shot, options);
  const FrameRange range = parse_frame_range("--frames", frames);
  shot.first_frame = range.first;
  shot.last_frame = range.last;
  check_number("--fps", fps, render::kMinFps, render::kMaxFps);
  check_number("--start", start_time, 0.0f, 1e7f);
  shot.fps = fps;
  shot.start_time = start_time;
  shot.clip = clip;
  shot.loop = loop;

  const scene::Scene scene = io::load_gltf(scene_path, gltf_options);
  const render::ShotRenderer renderer(scene, shot, options);
  const fs::path dir(out_dir);
  make_dir("--out", dir);
  io::check_writable((dir / "frame_0000.exr").string());
  fs::path preview_dir;
  if (previews) {
    preview_dir = dir / "preview";
    make_dir("--out", preview_dir);
  }

  const int count = shot.last_frame - shot.first_frame + 1;
  const bool tty = isatty(fileno(stderr));
  const auto start = std::chrono::steady_clock::now();
  // A frame's files are written while the next frame renders (compressing an EXR is mostly
  // serial); get() rethrows a write error before anything else is written.
  std::future<void> writing;
  for (int f = shot.first_frame; f <= shot.last_frame; ++f) {
    auto frame = std::make_shared<Image<float>>(renderer.render(f));
    if (render::object_coverage(frame->cview()) == 0.0f)
      throw Error(scene_path, fmt::format("frame {}: the camera sees nothing of the scene (all "
                                          "background); check --camera, --target and --fov",
                                          f));
    if (writing.valid()) writing.get();
    const std::string stem = fmt::format("frame_{:04d}", f);
    writing = std::async(std::launch::async, [frame, path = dir / (stem + ".exr"), preview_dir,
                                              stem, half = !full_float] {
      write_frame(*frame, path, preview_dir, stem, half);
    });
    if (!quiet) {
      const int done = f - shot.first_frame + 1;
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double per = elapsed / done;
      std::fprintf(stderr, "%semaki render: frame %d (%d/%d)  %.2f s/frame  ETA %.0f s%s",
                   tty ? "\r" : "", f, done, count, per, per * (count - done),
                   tty && done < count ? "   " : "\n");
      std::fflush(stderr);
    }
  }
  if (writing.valid()) writing.get();
  if (!quiet)
    std::fprintf(stderr, "emaki render: wrote %d frame(s) to %s\n", count, dir.string().c_str());
  return 0;
}

}  // namespace emaki::app
