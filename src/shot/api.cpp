#include "shot/api.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "core/stage_clock.h"
#include "pipeline/temporal_guide.h"
#include "shot/input_cache.h"
#include "shot/inputs.h"
#include "shot/memory.h"
#include "shot/parser.h"
#include "shot/plan.h"
#include "store/file_store.h"
#include "store/previews.h"
#include "store/qa_maps.h"

namespace emaki::shot {

namespace {

const pipeline::RunOptions& run_options(const Request& r) {
  return r;
}

// What one call's work runs under, on this thread only: its thread count and the shot's pixel
// budget. Nothing process-wide changes, so shots run at once on different threads (Python
// threads) keep their own settings.
struct Scope {
  ScopedThreadCount threads;
  ScopedMaxPixels pixels;
  Scope(const pipeline::Shot& shot, const Request& r)
      : threads(r.threads >= 0 ? r.threads : shot.threads),
        pixels(shot_max_pixels(shot.max_pixels)) {}
  explicit Scope(const pipeline::Shot& shot) : Scope(shot, Request{}) {}
};

using Exemplars = std::map<std::string, pipeline::ExemplarImages>;

// Refuses work whose estimated peak memory (the planner's figure for the largest kind of task
// it does) exceeds the request's max_memory_mb or what the machine has available, before the
// work starts. `exemplars`: the paintings, for the kinds whose peak depends on them.
void check_peak_memory(const pipeline::Shot& shot, const Request& r, const char* work,
                       std::initializer_list<TaskKind> kinds, const Exemplars& exemplars = {}) {
  double painting_pixels = 0;
  for (const auto& [name, e] : exemplars)
    painting_pixels += double(e.painting.width()) * e.painting.height();
  int64_t mb = 0;
  for (TaskKind k : kinds) mb = std::max(mb, task_memory_mb(shot, painting_pixels, k));
  check_memory(mb << 20, r.max_memory_mb << 20, shot.path,
               fmt::format("{} of {}x{} frames", work, shot.source.width, shot.source.height));
}

// The exemplars, loaded between two memory checks: the frames' share alone first, so a shot far
// too large is refused before its paintings are read, then with the paintings.
// `rendered`: as load_exemplars takes it.
Exemplars load_exemplars_checked(const pipeline::Shot& shot, const Request& r, const char* work,
                                 std::initializer_list<TaskKind> kinds,
                                 std::vector<std::string>* rendered = nullptr,
                                 InputCache* cache = nullptr) {
  check_peak_memory(shot, r, work, kinds);
  Exemplars exemplars = load_exemplars(shot, rendered, cache);
  check_peak_memory(shot, r, work, kinds, exemplars);
  return exemplars;
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

namespace {

RunResult run_with(const pipeline::Shot& shot, const Request& request, InputCache* cache) {
  pipeline::check_run_options(shot, run_options(request));
  const Scope scope(shot, request);
  const StageScope stage(request.stages, StageClock::kPrepare);
  // Everything that can fail on the inputs fails here, before a single output file exists.
  std::vector<std::string> rendered;
  const auto exemplars = load_exemplars_checked(
      shot, request, request.composite ? "the run" : "the layer task",
      {TaskKind::kLayer, request.composite ? TaskKind::kComposite : TaskKind::kLayer,
       TaskKind::kPasses},
      &rendered, cache);
  const auto frames = open_frames(shot, cache);
  // A layer task composites nothing: the prepare task has checked the compositing inputs.
  const pipeline::CompositeInputs ci =
      request.composite ? load_composite_inputs(shot, cache) : pipeline::CompositeInputs{};
  const pipeline::WeightMapImages maps = load_weight_maps(shot, cache);
  if (cache) cache->drop_unused();
  RunResult out;
  io::FileStore store(shot, io::StoreMode::kRun, access(request));  // locked until the end
  keep_references(shot, exemplars, rendered);
  out.report = pipeline::run_shot(shot, *frames, exemplars, ci, store, run_options(request), maps);
  const StageScope previews_stage(request.stages, StageClock::kPreviews);
  out.previews = previews(shot, request);
  return out;
}

}  // namespace

RunResult run(const pipeline::Shot& shot, const Request& request) {
  return run_with(shot, request, nullptr);
}

RunResult run(const pipeline::Shot& shot, const Request& request, InputCache& cache) {
  return run_with(shot, request, &cache);
}

CompositeResult composite(const pipeline::Shot& shot, const Request& request) {
  pipeline::check_run_options(shot, run_options(request));
  const Scope scope(shot, request);
  check_peak_memory(shot, request, "compositing", {TaskKind::kComposite});
  const auto frames = open_frames(shot);
  const pipeline::CompositeInputs ci = load_composite_inputs(shot);
  CompositeResult out;
  // Layers made with other settings are an error here: re-colouring never synthesizes.
  io::FileStore store(shot, io::StoreMode::kReadFinished, access(request));
  out.composited = pipeline::recomposite(shot, *frames, ci, store, run_options(request));
  out.previews = previews(shot, request);
  return out;
}

void prepare(const pipeline::Shot& shot, const Request& request) {
  const Scope scope(shot, request);
  // Everything that can fail on the inputs fails here, before a single task writes a file.
  std::vector<std::string> rendered;
  const Exemplars exemplars =
      load_exemplars_checked(shot, request, "the prepare task", {TaskKind::kPrepare}, &rendered);
  (void)open_frames(shot);
  (void)load_composite_inputs(shot);
  (void)load_weight_maps(shot);
  io::FileStore store(shot);
  store.prepare();
  // The layer tasks read the exemplars' reference passes from here instead of rendering them.
  keep_references(shot, exemplars, rendered);
}

namespace {

// The most object ids whose shares a kept advection field carries (store/kept_fields.h).
constexpr std::size_t kKeptShareIds = 4;

}  // namespace

int render_passes(const pipeline::Shot& shot, const Request& request) {
  pipeline::check_run_options(shot, run_options(request));
  if (shot.source.kind != pipeline::SourceKind::kScene) return 0;
  const Scope scope(shot, request);
  check_peak_memory(shot, request, "the passes task", {TaskKind::kPasses});
  const auto frames = open_frames(shot);
  io::FileStore store(shot, io::StoreMode::kRun, access(request));
  const int a = request.first_frame < 0 ? shot.source.first_frame : request.first_frame;
  const int b = request.last_frame < 0 ? shot.source.last_frame : request.last_frame;
  // Each frame's advection fields are made here, once, for every temporal layer task to read
  // (they would otherwise each compute them): from the frame before, read or rendered for the
  // chunk's first frame.
  const bool advects = std::any_of(shot.layers.begin(), shot.layers.end(),
                                   [](const pipeline::Layer& l) { return l.temporal.enabled; });
  std::optional<Image<float>> previous;
  int rendered = 0;
  for (int f = a; f <= b; ++f) {
    if (store.has_passes(f)) {
      previous.reset();
      continue;
    }
    Image<float> passes = frames->passes(f);
    if (advects && f > shot.source.first_frame) {
      if (!previous) previous = frames->passes(f - 1);
      std::vector<pipeline::KeptField> fields =
          pipeline::advection_fields(shot, previous->cview(), passes.cview(), f);
      // The id shares are a float plane per object id: with many objects they would outweigh the
      // frame's passes on disk, and the layers make them again in a few ms a frame.
      for (pipeline::KeptField& k : fields)
        if (k.field.shares.ids.size() > kKeptShareIds) k.field.shares = {};
      store.write_kept_fields(f, fields);
    }
    store.write_passes(f, passes.cview());
    previous = std::move(passes);
    ++rendered;
  }
  return rendered;
}

std::vector<std::string> write_previews(const pipeline::Shot& shot, const Request& request) {
  const Scope scope(shot, request);
  check_peak_memory(shot, request, "the previews task", {TaskKind::kPreviews});
  io::FileStore store(shot, io::StoreMode::kReadFinished, access(request));
  std::vector<std::string> written =
      io::write_previews(shot, shot.source.first_frame, shot.source.last_frame);
  // Asked for previews alone, a folder without them all composited is an error, not a success
  // that wrote nothing.
  const bool wanted =
      shot.outputs.mp4 || (shot.outputs.contact_sheet && shot.outputs.composite_png);
  if (wanted && written.empty())
    throw Error(shot.outputs.folder,
                fmt::format("frames {}-{} are not all composited under the shot's settings: no "
                            "previews to make; run the shot (or its composite tasks) first",
                            shot.source.first_frame, shot.source.last_frame));
  return written;
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

namespace {

// A measure's maps written through `store` as they come (Request::qa_maps); when the measure
// fails halfway, the destructor removes those written: no partial output.
class MapWriter {
 public:
  MapWriter(io::FileStore& store, const char* kind, const pipeline::Layer& layer, bool wanted)
      : store_(store), kind_(kind), layer_(layer), wanted_(wanted) {}
  ~MapWriter() {
    if (finished_) return;
    std::error_code ec;
    for (const std::string& f : written_) std::filesystem::remove(f, ec);
  }
  // The measure's callback, or none when no maps are wanted.
  std::function<void(int, const Image<float>&)> callback() {
    if (!wanted_) return {};
    return [this](int frame, const Image<float>& map) {
      written_.push_back(io::qa_map_png(store_.paths().folder, kind_, layer_.name, frame));
      store_.write_qa_map(kind_, layer_, frame, map.cview());
    };
  }
  void finish() { finished_ = true; }

 private:
  io::FileStore& store_;
  const char* kind_;
  const pipeline::Layer& layer_;
  bool wanted_, finished_ = false;
  std::vector<std::string> written_;
};

}  // namespace

FlickerResult flicker(const pipeline::Shot& shot, const std::string& layer,
                      const Request& request) {
  const Scope scope(shot, request);
  FlickerResult out;
  const pipeline::Layer* l = &measured_range(shot, layer, request, out.first_frame, out.last_frame);
  const auto frames = open_frames(shot);
  io::FileStore store(shot, io::StoreMode::kReadFinished);
  MapWriter writer(store, "flicker", *l, request.qa_maps);
  out.mean = pipeline::measure_flicker(
      *l, *frames, store, out.first_frame, out.last_frame,
      [&](const pipeline::FrameFlicker& f) { out.frames.push_back(f); }, writer.callback());
  writer.finish();
  return out;
}

GhostResult ghost(const pipeline::Shot& shot, const std::string& layer, const Request& request) {
  const Scope scope(shot, request);
  GhostResult out;
  const pipeline::Layer& l = measured_range(shot, layer, request, out.first_frame, out.last_frame);
  const auto exemplars =
      load_exemplars_checked(shot, request, "measuring ghosts", {TaskKind::kLayer});
  const auto frames = open_frames(shot);
  const pipeline::WeightMapImages maps = load_weight_maps(shot);
  io::FileStore store(shot, io::StoreMode::kReadFinished);
  const auto reference = [&](int f) {
    return pipeline::synthesize_alone(l, exemplars.at(l.exemplar), frames->passes(f).cview(), f,
                                      maps);
  };
  MapWriter writer(store, "ghost", l, request.qa_maps);
  out.total = pipeline::measure_ghost(
      l, *frames, store, out.first_frame, out.last_frame, reference,
      [&](const pipeline::FrameGhost& f) { out.frames.push_back(f); }, writer.callback());
  writer.finish();
  return out;
}

}  // namespace emaki::shot
