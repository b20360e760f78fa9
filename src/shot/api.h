// The shot API: the one surface every front end (the CLI, the farm submitter, the Python module)
// drives. open() reads and checks a shot file; run(), composite(), flicker() and ghost() open its
// inputs, lock its output folder and do the work. Errors are emaki::Error: a shot file's problems
// name its key ("layers.outline.mask"); a Request's name neutral fields ("frames", "layers",
// "layer", "threads") that each front end spells its own way (--frames, frames=).
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/flicker.h"
#include "pipeline/ghost.h"
#include "pipeline/run.h"
#include "pipeline/shot_description.h"
#include "shot/input_cache.h"

namespace emaki::shot {

// Reads and checks a shot file (shot/parser.h): nothing is written.
pipeline::Shot open(const std::string& path);
// The same from text; `path` names it in errors and anchors relative paths.
pipeline::Shot open_text(std::string_view text, const std::string& path);

// Which part of a shot to work on, and how: the pipeline's run options (frames, field "frames";
// layers, field "layers"; force; composite; progress) and what the shot module adds.
struct Request : pipeline::RunOptions {
  bool previews = true;  // contact sheet and MP4, as the shot's outputs ask
  int threads = -1;      // -1: the shot's `threads`; 0: all cores
  // A render-farm task beside other tasks of the same shot (shot/plan.h): shares the output
  // folder's lock, leaves clean-up to the prepare task and needs the folder prepared.
  bool farm_task = false;
  // Refuse the work when its estimated peak memory exceeds this many MB (0: no limit but what
  // the machine has available, which is always checked).
  int64_t max_memory_mb = 0;
  // flicker() and ghost(): also write each frame's map into the output folder, for emaki view's
  // overlay (store/qa_maps.h: OUTPUT/qa/flicker/LAYER/, OUTPUT/qa/ghost/LAYER/). run(): see
  // RunOptions::error_maps (OUTPUT/qa/error/LAYER/).
  bool qa_maps = false;
};

struct RunResult {
  pipeline::RunReport report;
  std::vector<std::string> previews;  // files written
};

// Synthesizes, composites and writes the requested frames and layers, resuming after the last
// finished frame. Every input is opened and checked before the first output is written.
RunResult run(const pipeline::Shot& shot, const Request& request);
// The same, with what `cache` holds of the shot's inputs (shot/input_cache.h) taken from it and
// what this run reads kept in it: the run again after a save of the painting (emaki lookdev)
// decodes the painting and synthesizes, but reads, decodes and renders nothing else again. The
// files written are those of a run without the cache.
RunResult run(const pipeline::Shot& shot, const Request& request, InputCache& cache);

struct CompositeResult {
  int composited = 0;  // frames
  std::vector<std::string> previews;
};

// Re-composites finished layers with the shot's current colours, blends and paper; layers made
// with other settings are an error naming the layer folder.
CompositeResult composite(const pipeline::Shot& shot, const Request& request);

// A farm's first task of a shot: checks every input, locks the folder alone, removes what a
// killed run left and brings every manifest up to date (deleting outputs made under other
// settings), so that the shot's other tasks can then run side by side.
void prepare(const pipeline::Shot& shot, const Request& request = {});

// Renders the requested frames' guide passes into the shot's pass cache (passes/), skipping
// frames already there; every later task reads them instead of rendering. A sequence source
// has its passes in files already: nothing to do. Returns the frames rendered.
int render_passes(const pipeline::Shot& shot, const Request& request);

// The contact sheet and MP4 the shot asks for, once every frame is composited. Returns the files
// written; throws Error naming the output folder when the shot asks for previews and its frames
// are not all composited under its settings (an unprepared or unfinished folder).
std::vector<std::string> write_previews(const pipeline::Shot& shot, const Request& request);

struct FlickerResult {
  int first_frame = 0, last_frame = 0;
  std::vector<pipeline::FrameFlicker> frames;  // first_frame + 1 .. last_frame
  pipeline::SequenceFlicker mean;
};

// The temporal error of a finished layer (field "layer" names it) over at least two frames.
FlickerResult flicker(const pipeline::Shot& shot, const std::string& layer, const Request& request);

struct GhostResult {
  int first_frame = 0, last_frame = 0;
  std::vector<pipeline::FrameGhost> frames;  // first_frame + 1 .. last_frame
  pipeline::GhostStats total;                // pooled over the frames' pixels
};

// Ghosts of a finished temporal layer (field "layer" names it) over at least two frames
// (pipeline/ghost.h): its frames against frame-by-frame results synthesized here (the same
// seeds a `temporal = false` run draws), which takes about one synthesis per frame.
GhostResult ghost(const pipeline::Shot& shot, const std::string& layer, const Request& request);

}  // namespace emaki::shot
