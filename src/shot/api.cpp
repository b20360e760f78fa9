#include "shot/api.h"

#include <fmt/format.h>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "shot/inputs.h"
#include "shot/parser.h"
#include "store/file_store.h"
#include "store/previews.h"

namespace emaki::shot {

namespace {

const pipeline::RunOptions& run_options(const Request& r) {
  return r;
}

void use_threads(const pipeline::Shot& shot, const Request& r) {
  set_thread_count(r.threads >= 0 ? r.threads : shot.threads);
}

io::StoreAccess access(const Request& r) {
  return r.farm_task ? io::StoreAccess::kFarmTask : io::StoreAccess::kAlone;
}

std::vector<std::string> previews(const pipeline::Shot& shot, const Request& r) {
  if (!r.previews) return {};
  return io::write_previews(shot, shot.source.first_frame, shot.source.last_frame);
}

}  // namespace

pipeline::Shot open(const std::string& path) {
  return load_shot(path);
}

pipeline::Shot open_text(std::string_view text, const std::string& path) {
  return parse_shot(text, path);
}

RunResult run(const pipeline::Shot& shot, const Request& request) {
  pipeline::check_run_options(shot, run_options(request));
  use_threads(shot, request);
  // Everything that can fail on the inputs fails here, before a single output file exists.
  const auto frames = open_frames(shot);
  const auto exemplars = load_exemplars(shot);
  const pipeline::CompositeInputs ci = load_composite_inputs(shot);
  const pipeline::WeightMapImages maps = load_weight_maps(shot);
  RunResult out;
  io::FileStore store(shot, io::StoreMode::kRun, access(request));  // locked until the end
  out.report = pipeline::run_shot(shot, *frames, exemplars, ci, store, run_options(request), maps);
  out.previews = previews(shot, request);
  return out;
}

CompositeResult composite(const pipeline::Shot& shot, const Request& request) {
  pipeline::check_run_options(shot, run_options(request));
  use_threads(shot, request);
  const auto frames = open_frames(shot);
  const pipeline::CompositeInputs ci = load_composite_inputs(shot);
  CompositeResult out;
  // Layers made with other settings are an error here: re-colouring never synthesizes.
  io::FileStore store(shot, io::StoreMode::kReadFinished, access(request));
  out.composited = pipeline::recomposite(shot, *frames, ci, store, run_options(request));
  out.previews = previews(shot, request);
  return out;
}

void prepare(const pipeline::Shot& shot) {
  // Everything that can fail on the inputs fails here, before a single task writes a file.
  (void)open_frames(shot);
  (void)load_exemplars(shot);
  (void)load_composite_inputs(shot);
  (void)load_weight_maps(shot);
  io::FileStore store(shot);
  store.prepare();
}

int render_passes(const pipeline::Shot& shot, const Request& request) {
  pipeline::check_run_options(shot, run_options(request));
  if (shot.source.kind != pipeline::SourceKind::kScene) return 0;
  use_threads(shot, request);
  const auto frames = open_frames(shot);
  io::FileStore store(shot, io::StoreMode::kRun, access(request));
  const int a = request.first_frame < 0 ? shot.source.first_frame : request.first_frame;
  const int b = request.last_frame < 0 ? shot.source.last_frame : request.last_frame;
  int rendered = 0;
  for (int f = a; f <= b; ++f) {
    if (store.has_passes(f)) continue;
    store.write_passes(f, frames->passes(f).cview());
    ++rendered;
  }
  return rendered;
}

std::vector<std::string> write_previews(const pipeline::Shot& shot, const Request& request) {
  io::FileStore store(shot, io::StoreMode::kReadFinished, access(request));
  return io::write_previews(shot, shot.source.first_frame, shot.source.last_frame);
}

// The layer and frame range a measure over finished frames (qa flicker, qa ghost) reads.
const pipeline::Layer& measured_range(const pipeline::Shot& shot, const std::string& layer,
                                      const Request& request, int& first, int& last) {
  const pipeline::Layer* l = shot.find_layer(layer);
  if (!l) throw Error(Error::Field{"layer"}, fmt::format("no layer '{}' in the shot", echo(layer)));
  first = request.first_frame < 0 ? shot.source.first_frame : request.first_frame;
  last = request.last_frame < 0 ? shot.source.last_frame : request.last_frame;
  if (last <= first) throw Error(Error::Field{"frames"}, "needs at least two frames");
  if (first < shot.source.first_frame || last > shot.source.last_frame)
    throw Error(Error::Field{"frames"},
                fmt::format("{}-{} is outside the shot's frames {}-{}", first, last,
                            shot.source.first_frame, shot.source.last_frame));
  return *l;
}

FlickerResult flicker(const pipeline::Shot& shot, const std::string& layer,
                      const Request& request) {
  use_threads(shot, request);
  FlickerResult out;
  const pipeline::Layer* l = &measured_range(shot, layer, request, out.first_frame, out.last_frame);
  const auto frames = open_frames(shot);
  io::FileStore store(shot, io::StoreMode::kReadFinished);
  out.mean =
      pipeline::measure_flicker(*l, *frames, store, out.first_frame, out.last_frame,
                                [&](const pipeline::FrameFlicker& f) { out.frames.push_back(f); });
  return out;
}

GhostResult ghost(const pipeline::Shot& shot, const std::string& layer, const Request& request) {
  use_threads(shot, request);
  GhostResult out;
  const pipeline::Layer& l = measured_range(shot, layer, request, out.first_frame, out.last_frame);
  const auto frames = open_frames(shot);
  const auto exemplars = load_exemplars(shot);
  const pipeline::WeightMapImages maps = load_weight_maps(shot);
  io::FileStore store(shot, io::StoreMode::kReadFinished);
  const auto reference = [&](int f) {
    return pipeline::synthesize_alone(l, exemplars.at(l.exemplar), frames->passes(f).cview(), f,
                                      maps);
  };
  out.total =
      pipeline::measure_ghost(l, *frames, store, out.first_frame, out.last_frame, reference,
                              [&](const pipeline::FrameGhost& f) { out.frames.push_back(f); });
  return out;
}

}  // namespace emaki::shot
