// `emaki run SHOT`: a whole shot — every layer of every frame, the temporal chain, compositing,
// previews — resuming after the last finished frame. `emaki composite SHOT` re-colours finished
// layers without synthesizing. `emaki qa flicker SHOT --layer NAME` measures temporal error.
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "apps/emaki/frame_range.h"
#include "apps/emaki/shot_options.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "io/shot_file.h"
#include "io/shot_inputs.h"
#include "pipeline/flicker.h"
#include "pipeline/run.h"
#include "render/passes.h"

namespace emaki::app {

namespace {

// --frames is optional here: empty leaves the shot's whole range (first/last_frame < 0).
void parse_frames(const std::string& text, pipeline::RunOptions& o) {
  if (text.empty()) return;
  const FrameRange r = parse_frame_range("--frames", text);
  o.first_frame = r.first;
  o.last_frame = r.last;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    if (end > start) out.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

std::string duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const int t = int(std::lround(s));
  return t >= 3600 ? fmt::format("{}h{:02d}m", t / 3600, t / 60 % 60)
                   : fmt::format("{}m{:02d}s", t / 60, t % 60);
}

// Progress on stderr: one updating line on a terminal, one line per step otherwise.
std::function<void(const pipeline::Progress&)> progress_printer(const char* command) {
  const bool tty = ::isatty(2);
  return [tty, command](const pipeline::Progress& p) {
    std::string line;
    if (p.layer.empty()) {
      line = fmt::format("emaki {}: frame {} compositing", command, p.frame);
    } else {
      const double eta = p.done > 0 ? p.elapsed_s / p.done * (p.total - p.done) : NAN;
      line =
          fmt::format("emaki {}: frame {} layer {} ({}/{}, {} elapsed, ETA {})", command, p.frame,
                      p.layer, p.done + 1, p.total, duration(p.elapsed_s), duration(eta));
    }
    if (tty)
      std::fprintf(stderr, "\r\033[K%s", line.c_str());
    else
      std::fprintf(stderr, "%s\n", line.c_str());
    std::fflush(stderr);
  };
}

void end_progress_line() {
  if (::isatty(2)) std::fprintf(stderr, "\n");
}

}  // namespace

int run_run(const Args& args) {
  CLI::App app{
      "Runs a shot file: synthesizes every layer of every frame (with the temporal "
      "chain), composites them over the paper and writes the outputs the shot asks "
      "for. Re-running resumes after the last finished frame.",
      "emaki run"};
  std::string shot_path, frames, layers;
  bool force = false, no_previews = false;
  int threads = -1;
  app.add_option("shot", shot_path, "the shot file (TOML; see docs/shot_file.md)")->required();
  app.add_option("--frames", frames, "FIRST-LAST or FRAME: only these frames (default: all)");
  app.add_option("--layers", layers, "comma-separated layer names (default: all)");
  app.add_flag("--force", force,
               "synthesize again frames that are already finished (outputs made with other "
               "settings are always redone)");
  app.add_flag("--no-previews", no_previews, "do not write the contact sheet and the MP4");
  app.add_option("--threads", threads, "worker threads, >= 0; 0 = all cores (default: the shot's)")
      ->check(CLI::NonNegativeNumber);
  if (parse_cli(app, args)) return 0;

  const pipeline::Shot shot = io::load_shot(shot_path);
  set_thread_count(threads >= 0 ? threads : shot.threads);
  pipeline::RunOptions options;
  parse_frames(frames, options);
  options.layers = split_commas(layers);
  options.force = force;
  options.progress = progress_printer("run");
  // Everything that can fail on the inputs fails here, before a single output file exists.
  const auto source = io::open_frames(shot);
  const auto exemplars = io::load_exemplars(shot);
  const pipeline::CompositeInputs ci = io::load_composite_inputs(shot);
  io::FileStore store(shot);
  const pipeline::RunReport r = pipeline::run_shot(shot, *source, exemplars, ci, store, options);
  end_progress_line();
  std::vector<std::string> previews;
  if (!no_previews)
    previews = io::write_previews(shot, shot.source.first_frame, shot.source.last_frame);
  std::fprintf(stderr,
               "emaki run: frames %d-%d: %d layer-frames synthesized, %d already finished, %d "
               "frames composited; outputs in %s\n",
               r.first_frame, r.last_frame, r.synthesized, r.reused, r.composited,
               shot.outputs.folder.c_str());
  for (const std::string& p : previews) std::fprintf(stderr, "emaki run: wrote %s\n", p.c_str());
  return 0;
}

int run_composite(const Args& args) {
  CLI::App app{
      "Re-composites a shot's finished layers with the colours, filters, blend modes "
      "and paper now in the shot file, without synthesizing again.",
      "emaki composite"};
  std::string shot_path, frames;
  bool no_previews = false;
  int threads = -1;
  app.add_option("shot", shot_path, "the shot file")->required();
  app.add_option("--frames", frames, "FIRST-LAST or FRAME (default: all)");
  app.add_flag("--no-previews", no_previews, "do not write the contact sheet and the MP4");
  app.add_option("--threads", threads, "worker threads, >= 0; 0 = all cores")
      ->check(CLI::NonNegativeNumber);
  if (parse_cli(app, args)) return 0;
  const pipeline::Shot shot = io::load_shot(shot_path);
  set_thread_count(threads >= 0 ? threads : shot.threads);
  pipeline::RunOptions options;
  parse_frames(frames, options);
  options.progress = progress_printer("composite");
  const auto source = io::open_frames(shot);
  const pipeline::CompositeInputs ci = io::load_composite_inputs(shot);
  // Layers made with other settings are an error here: re-colouring never synthesizes.
  io::FileStore store(shot, io::StoreMode::kReadFinished);
  const int n = pipeline::recomposite(shot, *source, ci, store, options);
  end_progress_line();
  if (!no_previews) io::write_previews(shot, shot.source.first_frame, shot.source.last_frame);
  std::fprintf(stderr, "emaki composite: %d frames composited into %s\n", n,
               shot.outputs.folder.c_str());
  return 0;
}

int run_qa(const Args& args) {
  if (args.empty() || args[0] != "flicker")
    throw Error("", "usage: emaki qa flicker SHOT --layer NAME [--frames A-B]");
  CLI::App app{
      "Temporal error of a layer's frames: mean |B'(t) - B'(t-1)| sampled along the "
      "renderer's motion vectors over pixels visible in both frames, split into scene "
      "objects and ground. Prints a table and a JSON line.",
      "emaki qa flicker"};
  std::string shot_path, frames, layer;
  int threads = -1;
  app.add_option("shot", shot_path, "the shot file")->required();
  app.add_option("--layer", layer, "the layer to measure")->required();
  app.add_option("--frames", frames, "FIRST-LAST (default: all)");
  app.add_option("--threads", threads, "worker threads, >= 0; 0 = all cores")
      ->check(CLI::NonNegativeNumber);
  if (parse_cli(app, Args(args.begin() + 1, args.end()))) return 0;
  const pipeline::Shot shot = io::load_shot(shot_path);
  set_thread_count(threads >= 0 ? threads : shot.threads);
  const pipeline::Layer* l = shot.find_layer(layer);
  if (!l) throw Error("--layer", fmt::format("no layer '{}' in the shot", layer));
  pipeline::RunOptions o;
  parse_frames(frames, o);
  const int a = o.first_frame < 0 ? shot.source.first_frame : o.first_frame;
  const int b = o.last_frame < 0 ? shot.source.last_frame : o.last_frame;
  if (b <= a) throw Error("--frames", "needs at least two frames");
  const auto source = io::open_frames(shot);
  io::FileStore store(shot, io::StoreMode::kReadFinished);
  for (int f = a; f <= b; ++f)
    if (!store.has_layer(*l, f))
      throw Error(fmt::format("layers.{}", layer),
                  fmt::format("frame {} is not synthesized yet", f));
  const int value_channels = l->single_colour ? 1 : 3;
  std::printf("%-6s %12s %12s %12s %9s\n", "frame", "all", "objects", "ground", "pixels");
  pipeline::SequenceFlicker mean;
  Image<float> prev = store.read_layer(*l, a), prev_passes = source->passes(a);
  for (int f = a + 1; f <= b; ++f) {
    Image<float> cur = store.read_layer(*l, f), cur_passes = source->passes(f);
    const int mask_channel = cur.channels() > value_channels ? value_channels : -1;
    const pipeline::FrameFlicker ff = pipeline::frame_flicker(
        cur.cview(), prev.cview(), cur_passes.cview(), prev_passes.cview(), mask_channel);
    std::printf("%-6d %12.5f %12.5f %12.5f %9ld\n", f, ff.all.mean(), ff.objects.mean(),
                ff.ground.mean(), ff.all.pixels);
    mean.add(ff);
    prev = std::move(cur);
    prev_passes = std::move(cur_passes);
  }
  std::printf("%-6s %12.5f %12.5f %12.5f\n", "mean", mean.all.mean(), mean.objects.mean(),
              mean.ground.mean());
  std::printf(
      "{\"layer\": \"%s\", \"frames\": [%d, %d], \"mean\": %.6f, \"objects\": %.6f, "
      "\"ground\": %.6f}\n",
      layer.c_str(), a, b, mean.all.mean(), mean.objects.mean(), mean.ground.mean());
  return 0;
}

}  // namespace emaki::app
