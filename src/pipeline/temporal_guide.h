// The temporal guide of a layer at one frame: B'(t-1) advected to frame t (temporal/), with the
// advection's confidence, and the seeds and settings every transfer of a layer derives from the
// layer. Shared by the run (pipeline/run.cpp) and `emaki qa ghost` (pipeline/ghost.cpp), which
// recomputes the guide a run used.
#pragma once

#include <cstdint>

#include "core/image.h"
#include "pipeline/shot.h"
#include "synth/synthesizer.h"
#include "temporal/advection.h"

namespace emaki::pipeline {

// The layer's synthesis settings with a seed.
synth::Params synth_params(const SynthSpec& s, uint64_t seed);

// Seeds depend on (layer seed, frame, which transfer: 0 main, 1 advection) only, so a resumed
// run draws exactly the numbers an uninterrupted one would.
uint64_t frame_seed(const Layer& l, int frame, int transfer);

// B'adv of `layer` at `frame`, from its value at frame - 1 (`previous`: value channels, then
// the mask coverage when it has a mask) and the passes of both frames. `mask`: the layer's mask
// at `frame` (empty: none). With layer.temporal.confidence the result carries the confidence.
temporal::Advection advect_layer(const Layer& layer, ImageView<const float> passes,
                                 const Image<float>& mask, ImageView<const float> previous,
                                 ImageView<const float> previous_passes, int frame);

}  // namespace emaki::pipeline
