// `emaki run SHOT`: a whole shot — every layer of every frame, the temporal chain, compositing,
// previews — resuming after the last finished frame. `emaki composite SHOT` re-colours finished
// layers without synthesizing. `emaki qa flicker|ghost SHOT --layer NAME` measures temporal
// error and ghosts.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "apps/emaki/shot_command.h"
#include "core/error.h"
#include "core/stage_clock.h"
#include "shot/api.h"

namespace emaki::app {

namespace {

// What an id of the object_id pass is in the shot: the ground, one of source.objects, or a
// mesh of the scene file.
std::string object_label(const pipeline::Shot& shot, int id) {
  if (id == 1) return "ground";
  const std::vector<pipeline::SceneObject>& objects = shot.source.objects;
  for (std::size_t i = 0; i < objects.size(); ++i)
    if (objects[i].id == id)
      return fmt::format("objects[{}] {}", i,
                         std::filesystem::path(objects[i].scene).filename().string());
  return "object";
}

void print_flicker(const pipeline::Shot& shot, const std::string& layer,
                   const shot::FlickerResult& r) {
  std::printf("%-6s %12s %12s %12s %9s\n", "frame", "all", "objects", "ground", "pixels");
  for (const pipeline::FrameFlicker& f : r.frames)
    std::printf("%-6d %12.5f %12.5f %12.5f %9ld\n", f.frame, f.all.mean(), f.objects.mean(),
                f.ground.mean(), f.all.pixels);
  const pipeline::SequenceFlicker& m = r.mean;
  std::printf("%-6s %12.5f %12.5f %12.5f\n", "mean", m.all.mean(), m.objects.mean(),
              m.ground.mean());
  // Per object id, over the frames in which the object was measured.
  std::printf("\n%-6s %-32s %12s %7s\n", "id", "object", "flicker", "frames");
  std::string by_id;
  for (const auto& [id, s] : m.by_id) {
    std::printf("%-6d %-32s %12.5f %7ld\n", id, object_label(shot, id).c_str(), s.mean(), s.pixels);
    by_id += fmt::format("{}\"{}\": {:.6f}", by_id.empty() ? "" : ", ", id, s.mean());
  }
  std::printf(
      "{\"layer\": \"%s\", \"frames\": [%d, %d], \"mean\": %.6f, \"objects\": %.6f, "
      "\"ground\": %.6f, \"by_id\": {%s}}\n",
      layer.c_str(), r.first_frame, r.last_frame, m.all.mean(), m.objects.mean(), m.ground.mean(),
      by_id.c_str());
}

// --maps of emaki qa flicker|ghost.
void bind_maps(CLI::App& app, const char* kind, bool& maps) {
  app.add_flag("--maps", maps,
               fmt::format("also write each frame's {} map into OUTPUT/qa/{}/LAYER/ (emaki "
                           "view's overlay)",
                           kind, kind));
}

void print_maps(const pipeline::Shot& shot, const char* kind, const std::string& layer,
                const shot::Request& request) {
  if (request.qa_maps)
    std::fprintf(stderr, "emaki qa %s: maps in %s/qa/%s/%s/\n", kind, shot.outputs.folder.c_str(),
                 kind, layer.c_str());
}

// --timings: one line per stage, then the total.
void print_timings(const StageClock& clock) {
  std::fprintf(stderr, "emaki run: %-10s %9s %9s\n", "stage", "wall s", "CPU s");
  StageClock::Seconds total;
  for (int k = 0; k < StageClock::kStageCount; ++k) {
    const auto s = StageClock::Stage(k);
    const StageClock::Seconds t = clock.seconds(s);
    std::fprintf(stderr, "emaki run: %-10s %9.2f %9.2f\n", StageClock::name(s), t.wall, t.cpu);
    total.wall += t.wall;
    total.cpu += t.cpu;
  }
  std::fprintf(stderr, "emaki run: %-10s %9.2f %9.2f\n", "total", total.wall, total.cpu);
}

}  // namespace

int run_run(const Args& args) {
  CLI::App app{
      "Runs a shot file: synthesizes every layer of every frame (with the temporal "
      "chain), composites them over the paper and writes the outputs the shot asks "
      "for. Re-running resumes after the last finished frame.",
      "emaki run"};
  ShotCommand c;
  bool force = false;
  c.bind(app, "FIRST-LAST or FRAME: only these frames (default: all)");
  app.add_option("--layers", c.layers, "comma-separated layer names (default: all)");
  app.add_flag("--force", force,
               "synthesize again frames that are already finished (outputs made with other "
               "settings are always redone)");
  bool error_maps = false;
  app.add_flag("--error-maps", error_maps,
               "also write each synthesized layer frame's synthesis error map into "
               "OUTPUT/qa/error/LAYER/ (emaki view's overlay)");
  bool timings = false;
  app.add_flag("--timings", timings,
               "also print where the time went: wall and CPU seconds (all threads) of each stage, "
               "named as the farm's tasks (prepare, passes, layers, composite, previews)");
  bool one_layer = false;
  app.add_flag("--one-layer-at-a-time", one_layer,
               "synthesize a frame's layers one after another instead of at once (less memory "
               "at once, more time)");
  c.bind_previews(app);
  if (parse_cli(app, args)) return 0;
  StageClock clock;
  const pipeline::Shot shot = shot::open(c.shot_path);
  shot::Request request = c.request("run");
  request.force = force;
  request.error_maps = error_maps;
  request.concurrent_layers = !one_layer;
  if (timings) request.stages = &clock;
  const shot::RunResult r = shot::run(shot, request);
  end_progress_line();
  if (timings) print_timings(clock);
  std::fprintf(stderr,
               "emaki run: frames %d-%d: %d layer-frames synthesized, %d already finished, %d "
               "frames composited; outputs in %s\n",
               r.report.first_frame, r.report.last_frame, r.report.synthesized, r.report.reused,
               r.report.composited, shot.outputs.folder.c_str());
  for (const std::string& p : r.previews) std::fprintf(stderr, "emaki run: wrote %s\n", p.c_str());
  for (const pipeline::RunReport::Stale& st : r.report.stale) {
    const bool one = st.first == st.last;
    const std::string range =
        one ? fmt::format("{}", st.first) : fmt::format("{}-{}", st.first, st.last);
    std::fprintf(stderr,
                 "emaki run: warning: layer %s: frame%s %s %s made from frame %d as it was before "
                 "this run changed it; `emaki run %s --force --frames %s --layers %s` redoes "
                 "%s\n",
                 st.layer.c_str(), one ? "" : "s", range.c_str(), one ? "was" : "were",
                 st.first - 1, c.shot_path.c_str(), range.c_str(), st.layer.c_str(),
                 one ? "it" : "them");
  }
  return 0;
}

int run_composite(const Args& args) {
  CLI::App app{
      "Re-composites a shot's finished layers with the colours, filters, blend modes "
      "and paper now in the shot file, without synthesizing again.",
      "emaki composite"};
  ShotCommand c;
  c.bind(app, "FIRST-LAST or FRAME (default: all)");
  c.bind_previews(app);
  if (parse_cli(app, args)) return 0;
  const pipeline::Shot shot = shot::open(c.shot_path);
  const shot::CompositeResult r = shot::composite(shot, c.request("composite"));
  end_progress_line();
  std::fprintf(stderr, "emaki composite: %d frames composited into %s\n", r.composited,
               shot.outputs.folder.c_str());
  return 0;
}

namespace {

int run_qa_flicker(const Args& args) {
  CLI::App app{
      "Temporal error of a layer's frames: mean |B'(t) - B'(t-1)| sampled along the "
      "renderer's motion vectors over pixels visible in both frames, split into scene "
      "objects and ground, and per object id. Prints tables and a JSON line.",
      "emaki qa flicker"};
  ShotCommand c;
  std::string layer;
  c.bind(app, "FIRST-LAST (default: all)");
  app.add_option("--layer", layer, "the layer to measure")->required();
  bind_maps(app, "flicker", c.request_maps);
  if (parse_cli(app, args)) return 0;
  const pipeline::Shot shot = shot::open(c.shot_path);
  shot::Request request = c.request("qa");
  request.progress = nullptr;
  print_flicker(shot, layer, shot::flicker(shot, layer, request));
  print_maps(shot, "flicker", layer, request);
  return 0;
}

int run_qa_ghost(const Args& args) {
  CLI::App app{
      "Ghosts of a temporal layer: over pixels whose surface was hidden at t-1 (motion, "
      "object id and rest position), the share of the temporal guide's pull that came from "
      "another object, and the mean |temporal - frame-by-frame| there (the frame-by-frame "
      "results are synthesized, about one synthesis per frame). Prints a table and a JSON "
      "line.",
      "emaki qa ghost"};
  ShotCommand c;
  std::string layer;
  c.bind(app, "FIRST-LAST (default: all)");
  app.add_option("--layer", layer, "the layer to measure")->required();
  bind_maps(app, "ghost", c.request_maps);
  if (parse_cli(app, args)) return 0;
  const pipeline::Shot shot = shot::open(c.shot_path);
  shot::Request request = c.request("qa");
  request.progress = nullptr;
  const shot::GhostResult r = shot::ghost(shot, layer, request);
  print_maps(shot, "ghost", layer, request);
  std::printf("%-6s %9s %12s %12s %14s\n", "frame", "hidden", "ghost share", "diff hidden",
              "diff visible");
  for (const pipeline::FrameGhost& f : r.frames)
    std::printf("%-6d %9ld %12.4f %12.5f %14.5f\n", f.frame, f.stats.hidden, f.stats.ghost_share(),
                f.stats.diff(), f.stats.visible_diff());
  const pipeline::GhostStats& t = r.total;
  std::printf("%-6s %9ld %12.4f %12.5f %14.5f\n", "all", t.hidden, t.ghost_share(), t.diff(),
              t.visible_diff());
  std::printf(
      "{\"layer\": \"%s\", \"frames\": [%d, %d], \"hidden_pixels\": %ld, "
      "\"ghost_share\": %.6f, \"diff_hidden\": %.6f, \"diff_visible\": %.6f}\n",
      layer.c_str(), r.first_frame, r.last_frame, t.hidden, t.ghost_share(), t.diff(),
      t.visible_diff());
  return 0;
}

}  // namespace

int run_qa(const Args& args) {
  const std::string usage =
      "usage: emaki qa flicker|ghost SHOT --layer NAME [--frames A-B] [--maps]";
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::printf(
        "Quality checks of a finished layer.\n%s\n\n"
        "  flicker  temporal error along the motion vectors, per object and ground\n"
        "  ghost    what a temporal layer carried over from another object where a surface "
        "appears\n",
        usage.c_str());
    return 0;
  }
  if (args.empty() || (args[0] != "flicker" && args[0] != "ghost")) throw Error("", usage);
  const Args rest(args.begin() + 1, args.end());
  return args[0] == "flicker" ? run_qa_flicker(rest) : run_qa_ghost(rest);
}

}  // namespace emaki::app
