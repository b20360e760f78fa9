// `emaki lookdev SHOT --frames 0,24,47 [--scale 0.5]`: a few frames of a shot at preview size,
// made again whenever the painting(s), the shot file or the passes are saved, on emaki view's
// page (src/view/). Frames run frame by frame (no temporal chain), or with --temporal each from
// its predecessor made frame by frame, into their own folder. A save after a quiet time starts
// a run at once; a save during a run stops it (within the synthesis in progress: the engine's
// cancel hook) and the run starts over once the saves settle.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "apps/emaki/staging_options.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/utf8.h"
#include "shot/api.h"
#include "shot/plan.h"
#include "synth/synthesizer.h"
#include "view/rerun.h"
#include "view/server.h"

namespace emaki::app {

int serve_until_signal(view::Server& server);
void add_server_options(CLI::App& app, view::ServerOptions& o);

namespace {

namespace fs = std::filesystem;

struct LookdevOptions {
  std::string shot;
  std::string frames = "";
  double scale = 0.5;
  std::string out;        // default: the shot's output folder + ".lookdev"
  bool temporal = false;  // each frame made from its predecessor (the chain's first step)
};

std::vector<int> parse_frame_list(const std::string& text, const pipeline::Shot& shot) {
  std::vector<int> frames;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string part = text.substr(start, end - start);
    char* stop = nullptr;
    const long f = std::strtol(part.c_str(), &stop, 10);
    if (part.empty() || *stop != '\0' || f < shot.source.first_frame || f > shot.source.last_frame)
      throw Error("--frames",
                  fmt::format("expected frames of the shot ({}-{}) separated by commas, "
                              "got '{}'",
                              shot.source.first_frame, shot.source.last_frame, echo(text)));
    frames.push_back(int(f));
    start = end + 1;
  }
  return frames;
}

// The shot as lookdev runs it: preview size, every layer frame by frame unless `temporal`, its
// own folder, no movie or contact sheet.
pipeline::Shot preview_shot(const std::string& path, double scale, const std::string& out,
                            bool temporal = false) {
  pipeline::Shot s = shot::open(path);
  if (scale != 1.0 && s.source.kind != pipeline::SourceKind::kScene)
    throw Error("--scale", "a shot of studio passes is previewed at their own size (--scale 1)");
  s.source.maps_width = s.source.width;  // painted weight maps are resampled to the preview
  s.source.maps_height = s.source.height;
  s.source.width = std::max(8, int(std::lround(s.source.width * scale)));
  s.source.height = std::max(8, int(std::lround(s.source.height * scale)));
  s.source.render.width = s.source.width;
  s.source.render.height = s.source.height;
  s.source.render.outline_width = float(s.source.render.outline_width * scale);
  // The paintings shrink with the frame, so that the preview's strokes keep their size against
  // it (a full-size painting would paint a half-size frame with strokes twice as large).
  for (pipeline::Exemplar& e : s.exemplars)
    if (e.kind == pipeline::ExemplarKind::kMatcap) e.scale = scale;
  if (!temporal)
    for (pipeline::Layer& l : s.layers) l.temporal.enabled = false;
  s.outputs.folder = out;
  s.outputs.mp4 = false;
  s.outputs.contact_sheet = false;
  s.outputs.layered_exr = false;
  return s;
}

// What a save can change: the shot file, each painting, pass file and painted weight map.
std::vector<fs::path> watched_files(const pipeline::Shot& s) {
  std::vector<fs::path> files{s.path};
  for (const pipeline::Exemplar& e : s.exemplars) {
    if (!e.painting.empty()) files.emplace_back(e.painting);
    if (!e.passes.empty()) files.emplace_back(e.passes);
  }
  for (const pipeline::Layer& l : s.layers)
    for (const auto& g : l.guides)
      if (!g.map_image.empty()) files.emplace_back(g.map_image);
  return files;
}

struct StaleRun {};

// The page's status line and the figures a bench reads (GET /api/status).
struct Status {
  std::mutex mutex;
  std::string message = "starting";
  int generation = 0;
  double seconds = 0;
  std::string json() {
    std::lock_guard lock(mutex);
    return fmt::format("{{\"message\":{},\"generation\":{},\"seconds\":{:.3f}}}",
                       shot::json_string(valid_utf8_or_marks(message), "status"), generation,
                       seconds);
  }
  void set(std::string m, int g = -1, double s = -1) {
    std::lock_guard lock(mutex);
    message = std::move(m);
    if (g >= 0) generation = g, seconds = s;
    std::fprintf(stderr, "emaki lookdev: %s\n", message.c_str());
  }
};

// One run over the frames; returns whether it finished (not stale). `cache` keeps the inputs a
// save did not change from one run to the next.
bool run_frames(const LookdevOptions& o, const std::vector<int>& frames,
                const std::atomic<bool>& stale, Status& status, shot::InputCache& cache) {
  const auto t0 = std::chrono::steady_clock::now();
  const pipeline::Shot s = preview_shot(o.shot, o.scale, o.out, o.temporal);
  for (const int f : frames) {
    if (stale) return false;
    shot::Request r;
    r.first_frame = r.last_frame = f;
    // With --temporal, frame f - 1 as a chain's first frame and f from it along the chain.
    if (o.temporal && f > s.source.first_frame) r.first_frame = r.chain_from = f - 1;
    r.force = true;
    r.previews = false;
    r.error_maps = true;         // the page's overlay: where the painting has no good match
    r.concurrent_layers = true;  // a preview frame is small: its layers at once fill the cores
    r.cancel = [&] { return stale.load(); };  // a save stops the synthesis in progress too
    r.progress = [&](const pipeline::Progress& p) {
      if (stale) throw StaleRun{};
      status.set(fmt::format("frame {} {}", p.frame, p.layer.empty() ? "compositing" : p.layer));
    };
    shot::run(s, r, cache);
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::lock_guard lock(status.mutex);
  ++status.generation;
  status.seconds = seconds;
  status.message = fmt::format("frames made in {:.2f} s", seconds);
  std::fprintf(stderr, "emaki lookdev: run %d: %zu frames in %.2f s\n", status.generation,
               frames.size(), seconds);
  return true;
}

}  // namespace

int run_lookdev(const Args& args) {
  CLI::App app{
      "Makes a few frames of a shot at preview size and makes them again on every save of the "
      "painting(s), the shot file or the passes; shows them on emaki view's page (its URL is "
      "printed). Layers run frame by frame, or with --temporal each frame from its predecessor. "
      "Ctrl-C stops.",
      "emaki lookdev"};
  LookdevOptions o;
  view::ServerOptions server_options;
  app.add_option("shot", o.shot, "the shot file (TOML)")->required();
  app.add_option("--frames", o.frames, "frames to make, e.g. 0,24,47 (default: the first)");
  app.add_option("--scale", o.scale, "preview size relative to the shot's (default 0.5)");
  app.add_option("--out", o.out, "output folder (default: the shot's, with '.lookdev')");
  app.add_flag("--temporal", o.temporal,
               "make each frame from its predecessor along the temporal chain (the frame before "
               "is made frame by frame, and shown too): the chain's first step, at twice the cost");
  add_server_options(app, server_options);
  if (parse_cli(app, args)) return 0;
  if (!(o.scale > 0 && o.scale <= 1)) throw Error("--scale", "expected a number in (0, 1]");
  const pipeline::Shot shot = shot::open(o.shot);
  const std::vector<int> frames = o.frames.empty() ? std::vector<int>{shot.source.first_frame}
                                                   : parse_frame_list(o.frames, shot);
  if (o.out.empty()) o.out = shot.outputs.folder + ".lookdev";
  (void)preview_shot(o.shot, o.scale, o.out);  // a bad --scale fails before the page starts
  fs::create_directories(o.out);
  Status status;
  view::Server server({o.out}, server_options, [&] { return status.json(); });
  shot::InputCache cache;  // used by the rerun's thread alone
  view::Rerun rerun(watched_files(shot), [&](const std::atomic<bool>& stale) {
    try {
      run_frames(o, frames, stale, status, cache);
    } catch (const StaleRun&) {
      status.set("a newer save: starting over");
    } catch (const synth::Cancelled&) {
      status.set("a newer save: starting over");
    } catch (const std::exception& e) {
      status.set(std::string("error: ") + e.what());
    }
  });
  rerun.start();
  const int code = serve_until_signal(server);
  rerun.stop();
  return code;
}

}  // namespace emaki::app
