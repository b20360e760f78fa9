// One layer at one frame: a layer's exemplar cut once into what every frame's synthesis reads,
// and the synthesis of one frame from it (with B'(t-1) carried along, when its temporal chain
// continues). What run_shot (pipeline/run.h) runs for each layer and frame; internal to the
// pipeline module.
#pragma once

#include <memory>
#include <vector>

#include "core/image.h"
#include "pipeline/run.h"
#include "pipeline/shot_description.h"
#include "pipeline/temporal_guide.h"
#include "pipeline/tone_anchor.h"
#include "temporal/advection.h"

namespace emaki::pipeline::detail {

// A layer with its exemplar cut into what every frame's synthesis reads.
struct PreparedLayer {
  const Layer* layer = nullptr;
  int value_channels = 1;
  Image<float> style;  // A': the touch (1 channel) or the painting's RGB
  // One per layer->guides entry: ExemplarImages::guides' or cut here.
  std::vector<std::shared_ptr<const Image<float>>> source_guides;
  std::vector<const Image<float>*> painted_maps;  // per guide: its painted weight map, or null
  Image<float> temporal_style;  // A' low-passed for the temporal guide (guide_sigma), or empty
  TemporalSharpening sharpening;
  AnchorExemplar anchor;  // the tone anchor's exemplar side (TemporalSpec::anchor), or empty
};

// The layer's exemplar cut for frames of frame_width x frame_height.
PreparedLayer prepare(const Layer& layer, const ExemplarImages& ex, const WeightMapImages& maps,
                      int frame_width, int frame_height);

// A layer's result at one frame: its value and, for a temporal layer, the field that made it
// (the next frame's warm start).
struct LayerFrame {
  Image<float> value;
  Image<int32_t> nnf;
  Image<float> error;       // when asked: the synthesis error (synth::Result::error)
  Image<float> confidence;  // at a temporal frame: the temporal guide's, else empty
};

// B'(t-1) of layer `p` carried to `frame` (advect_layer with the layer's mask and whether it
// keeps the temporal pair): what its synthesis at `frame` takes from frame - 1 and its passes.
temporal::Advection advect_previous(const PreparedLayer& p, ImageView<const float> passes,
                                    int frame, const Image<float>& previous,
                                    ImageView<const float> previous_passes,
                                    AdvectionFields* fields);

// One layer at one frame. `advected_in`: when the temporal chain continues, B'(t-1) of this layer
// carried to t (advect_previous(), taken); `previous_nnf`: the field of t-1 (empty: none, the
// whole pyramid runs). `fields`: the frame's advection fields, shared by its layers. `o`: the
// run's error maps and cancel hook, if any.
LayerFrame synthesize_layer(const PreparedLayer& p, ImageView<const float> passes, int frame,
                            temporal::Advection* advected_in, ImageView<const int32_t> previous_nnf,
                            AdvectionFields* fields, const RunOptions* o = nullptr);

}  // namespace emaki::pipeline::detail
