// Running a shot: layers x frames, each layer synthesized from its exemplar under its mask, the
// temporal chain (advection of the previous stylized frame), compositing, and resuming after
// the last finished frame. Files are the Store's business (io/); this code only decides what
// to compute and in which order.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/stage_clock.h"
#include "pipeline/frames.h"
#include "pipeline/shot_description.h"

namespace emaki::pipeline {

// An exemplar ready for synthesis: its painting (RGB float, as in its file) and the guide passes
// it was painted over (kChannelCount channels, the painting's size).
struct ExemplarImages {
  Image<float> painting;
  Image<float> passes;  // may be empty when `guides` holds every pass its layers use
  // Passes cut out of `passes` already (extract_pass), by pass name, which the layers take
  // instead of cutting them again (shot/input_cache.h keeps them between runs).
  std::map<std::string, std::shared_ptr<const Image<float>>> guides;
};

// Where layer results and frame outputs live. A layer frame is finished once has_layer says so:
// writes must be atomic so that a killed run never leaves a half frame that looks finished.
class Store {
 public:
  virtual ~Store() = default;
  virtual bool has_layer(const Layer& layer, int frame) const = 0;
  // The layer's values (1 or 3 channels) and, for a masked layer, the mask coverage last.
  virtual Image<float> read_layer(const Layer& layer, int frame) const = 0;
  virtual void write_layer(const Layer& layer, int frame, ImageView<const float> value) = 0;
  // A temporal layer's field at `frame` (the next frame's warm start) with the digest of the
  // value it made (value_digest()), kept so that a resumed run starts the next frame from it
  // exactly as an uninterrupted run does. Written before write_layer (whose file marks the frame
  // finished). read_field gives an empty image when there is none, or when what is there is not
  // that frame's field of a value with `digest` and the shot's size (the next frame then runs
  // the whole pyramid). The defaults keep nothing.
  virtual void write_field(const Layer& layer, int frame, ImageView<const int32_t> nnf,
                           uint64_t digest) {
    (void)layer, (void)frame, (void)nnf, (void)digest;
  }
  virtual Image<int32_t> read_field(const Layer& layer, int frame, uint64_t digest) const {
    (void)layer, (void)frame, (void)digest;
    return {};
  }
  // Removes the layer's field at `frame`, if there is one (TemporalSpec::keep_every_field false).
  virtual void remove_field(const Layer& layer, int frame) { (void)layer, (void)frame; }
  // A QA map of the layer at `frame` (pipeline/qa_maps.h), `kind` naming it: "error" (the
  // synthesis error, RunOptions::error_maps), "flicker", "ghost". The default keeps nothing.
  virtual void write_qa_map(const std::string& kind, const Layer& layer, int frame,
                            ImageView<const float> map) {
    (void)kind, (void)layer, (void)frame, (void)map;
  }
  // True when every per-frame output (composite, layered EXR, ...) of `frame` exists.
  virtual bool has_frame(int frame) const = 0;
  // `composite` is RGBA; `layers` are in shot.layers order.
  virtual void write_frame(int frame, ImageView<const float> composite,
                           const std::vector<ImageView<const float>>& layers,
                           ImageView<const float> passes) = 0;
};

struct Progress {
  int frame = 0;
  std::string layer;        // empty: compositing
  int done = 0, total = 0;  // layer-frames synthesized so far / to synthesize in this run
  double elapsed_s = 0.0;
};

// shot::Request extends it (slicing to it is how the shot API hands a request down).
struct RunOptions {
  int first_frame = -1, last_frame = -1;  // -1: the shot's range
  // >= 0: the temporal chain starts at this frame (at most first_frame), which runs as the
  // shot's first frame does (emaki lookdev --temporal); -1: at the shot's first frame.
  int chain_from = -1;
  std::vector<std::string> layers;  // empty: all
  bool force = false;               // synthesize again even when finished
  bool composite = true;            // false: layers only (a farm's layer task)
  bool error_maps = false;  // each synthesized layer frame's error map, to Store::write_qa_map
  // The layers a frame needs synthesized at once rather than one after another: the same
  // results, less wall time (a layer's synthesis leaves threads idle between its PatchMatch
  // rounds, which another layer's work fills), more memory at once.
  bool concurrent_layers = false;
  std::function<void(const Progress&)> progress;
  // Polled during each synthesis (synth::Params::cancel): true stops the run with
  // synth::Cancelled, leaving the layer frames written before it; false changes nothing.
  std::function<bool()> cancel;
  // When set, charged the run's work by stage (core/stage_clock.h): run_shot charges its frames'
  // passes (and their advection fields) to kPasses, compositing and the frames' outputs to
  // kComposite, the rest to kLayers. Changes no result.
  StageClock* stages = nullptr;
};

struct RunReport {
  int synthesized = 0;                  // layer-frames synthesized
  int reused = 0;                       // layer-frames read back (finished before)
  int composited = 0;                   // frames composited
  int first_frame = 0, last_frame = 0;  // frames visited (the chain may start before --frames)
  // A temporal layer's finished frames after the run's last frame, made from that frame as it was
  // before this (forced) run replaced it with a different one: `first`-`last` of `layer` no
  // longer continue the chain.
  struct Stale {
    std::string layer;
    int first = 0, last = 0;
  };
  std::vector<Stale> stale;
};

// The paper as composite_frame last made it (the frame's size, the working space); see
// CompositeInputs::made_paper.
struct MadePaper;
std::shared_ptr<MadePaper> new_made_paper();

// The inputs of compositing that do not change from frame to frame.
struct CompositeInputs {
  Image<float> paper;  // empty: flat paper colour
  // The paper made once for every frame (composite::paper_image, in the working space), by the
  // first composite_frame call; made again when the shot's paper keys, the frame's size or the
  // working space differ. Copies share it.
  std::shared_ptr<MadePaper> made_paper = new_made_paper();
};

// Painted guide weight maps (GuideSpec::map_image) by path: one channel each, the shot's size.
using WeightMapImages = std::map<std::string, Image<float>>;

// A digest of a layer value's samples (bit patterns, size and channels), which ties a stored
// field to the value it made.
uint64_t value_digest(ImageView<const float> value);

// Runs (or resumes) the shot over the requested frames and layers. `exemplars` maps exemplar
// names to their images; `weight_maps` holds every painted weight map the layers name. Throws
// emaki::Error for what a user can fix (a size that does not match; an unknown layer in
// options.layers or a range outside the shot, named by the fields "layers" and "frames").
RunReport run_shot(const Shot& shot, const FrameSource& frames,
                   const std::map<std::string, ExemplarImages>& exemplars,
                   const CompositeInputs& composite_inputs, Store& store, const RunOptions& options,
                   const WeightMapImages& weight_maps = {});

// `layer` at `frame` synthesized alone, without the temporal guide: what `temporal = false`
// gives (the frame-by-frame reference of `emaki qa ghost`).
Image<float> synthesize_alone(const Layer& layer, const ExemplarImages& exemplar,
                              ImageView<const float> passes, int frame,
                              const WeightMapImages& weight_maps = {});

// Throws what run_shot would throw for `options` alone (fields "layers" and "frames"), so that a
// front end can refuse a request before it creates an output file.
void check_run_options(const Shot& shot, const RunOptions& options);

// Re-composites finished layer frames with the shot's current colours, blends and paper,
// without synthesizing. Returns the number of frames written.
int recomposite(const Shot& shot, const FrameSource& frames,
                const CompositeInputs& composite_inputs, Store& store, const RunOptions& options);

// The composite of one frame: the layers (shot.layers order) over the paper.
Image<float> composite_frame(const Shot& shot, ImageView<const float> passes,
                             const std::vector<ImageView<const float>>& layers,
                             const CompositeInputs& composite_inputs);

// A grid of thumbnails (RGB), `columns` wide, each thumbnail `thumb_width` pixels wide.
Image<float> contact_sheet(const std::vector<Image<float>>& frames, int columns, int thumb_width);

}  // namespace emaki::pipeline
