// The temporal guide of a layer at one frame: B'(t-1) advected to frame t (temporal/), with the
// advection's confidence, and the seeds and settings every transfer of a layer derives from the
// layer. Shared by the run (pipeline/run.cpp) and `emaki qa ghost` (pipeline/ghost.cpp), which
// recomputes the guide a run used.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/image.h"
#include "core/stage_clock.h"
#include "pipeline/frames.h"
#include "pipeline/shot_description.h"
#include "synth/synthesizer.h"
#include "temporal/advection.h"

namespace emaki::pipeline {

// The layer's synthesis settings with a seed.
synth::Params synth_params(const SynthSpec& s, uint64_t seed);

// Seeds depend on (layer seed, frame, which transfer: 0 main, 1 advection) only, so a resumed
// run draws exactly the numbers an uninterrupted one would.
uint64_t frame_seed(const Layer& l, int frame, int transfer);

// What a temporal layer's chain does against the blur that carrying it adds frame after frame:
// its temporal guide's low-pass (TemporalSpec::guide_sigma) and the warm start's first estimate
// (synth::Params::warm_sharp_estimate). A value set in the spec (>= 0) is taken as it is (the
// estimate's default is 0); negative, it comes from how many pixels the frame has against the
// painting: none up to 12 % of the painting's, all (sigma 1 pixel, the estimate each pixel's
// own match) from 40 %, linear between, and none for a layer without a temporal guide
// (weight 0). The chain loses the painting's grain with that share, not with the frame's size
// (docs/design/long-shots.md).
struct TemporalSharpening {
  float guide_sigma = 0.0f;
  float sharp_estimate = 0.0f;
  int coherence_radius = 0;  // TemporalSpec::coherence_radius: 3 x that share, rounded
};
TemporalSharpening temporal_sharpening(const TemporalSpec& t, int frame_width, int frame_height,
                                       int painting_width, int painting_height);

// The main transfer's uniformity at a temporal frame: TemporalSpec::uniformity everywhere, plus
// flat_uniformity inside the flat areas of the layer's target guides (`guides`, within `mask`).
// Sets params.uniformity and, with flat_uniformity, params.uniformity_map, held by `map`.
void temporal_uniformity(const TemporalSpec& t, const std::vector<Image<float>>& guides,
                         const Image<float>& mask, synth::Params& params, Image<float>& map);

// One frame's advection fields, shared by the layers that advect with the same guide, patch size
// and seed: a field depends on neither a layer's value nor its mask (temporal::advection_field),
// so the layers of a shot, which differ in those, match once per frame instead of once each.
class AdvectionFields {
 public:
  // `kept`, when given, is asked once, before the first field is computed, for the fields made
  // ahead (FrameSource::kept_fields): a field found there is not computed again. `clock`, when
  // given, is charged the fields' reading and computing as StageClock::kPasses (the farm's passes
  // task makes them).
  // Not synchronized: a run computes a frame's fields on one thread before its layers start;
  // layers synthesized at once (RunOptions::concurrent_layers) only find() them.
  explicit AdvectionFields(std::function<std::vector<KeptField>()> kept = {},
                           StageClock* clock = nullptr);
  const temporal::AdvectionField& get(const Layer& layer, int frame,
                                      const std::function<temporal::AdvectionField()>& compute);
  // The field get() gave `layer` at `frame`, or null when it has not been computed.
  const temporal::AdvectionField* find(const Layer& layer, int frame) const;
  // Every field, moved out (the object then holds none).
  std::vector<KeptField> release();
  // What every layer cuts from a frame's passes (the frame's or the one before), cut once:
  // advection_guide(passes, guide), and the motion (2 channels). `passes` must stay the same
  // image while this object lives.
  const Image<float>& guide(ImageView<const float> passes, AdvectionGuide guide);
  const Image<float>& motion(ImageView<const float> passes);
  // Lets go of what only the advection reads: the cuts, and each field's error, visibility and id
  // shares; the fields' nnf stay (the warm starts carry B'(t-1)'s field along them).
  void keep_only_warm_start_fields();

 private:
  struct Cut {
    const float* passes;
    int what;  // an AdvectionGuide, or -1: the motion
    Image<float> image;
  };
  const Image<float>& cut(ImageView<const float> passes, int what);
  std::vector<std::unique_ptr<Cut>> cuts_;  // stable addresses
  std::function<std::vector<KeptField>()> kept_;
  StageClock* clock_;
  std::vector<std::unique_ptr<KeptField>> entries_;  // stable addresses
};

// The advection fields of `frame` (after the shot's first) for the shot's temporal layers, one
// per distinct (guide, patch size, seed), from the passes of frame - 1 and of frame: the fields
// the layers' synthesis computes, made ahead of it (the farm's passes task keeps them).
std::vector<KeptField> advection_fields(const Shot& shot, ImageView<const float> previous_passes,
                                        ImageView<const float> passes, int frame);

// B'adv of `layer` at `frame`, from its value at frame - 1 (`previous`: value channels, then
// the mask coverage when it has a mask) and the passes of both frames. `mask`: the layer's mask
// at `frame` (empty: none). With layer.temporal.confidence the result carries the confidence.
// `fields`: the frame's fields so far (the field is taken from there, or computed and added);
// null: computed for this call alone — the same field either way. `value` false: the
// confidence alone (temporal::AdvectionInputs::value).
temporal::Advection advect_layer(const Layer& layer, ImageView<const float> passes,
                                 const Image<float>& mask, ImageView<const float> previous,
                                 ImageView<const float> previous_passes, int frame,
                                 AdvectionFields* fields = nullptr, bool value = true);

// The warm start of a layer's main transfer at a frame (TemporalSpec::warm_start): `previous`,
// its field at the frame before (Result::nnf: the exemplar patch centre per pixel, (-1, -1)
// where it was not synthesized), carried along the frame's advection `field`. Pixel p starts at
// the exemplar patch that the pixel of t-1 it matches used; where that pixel had none, at
// (-1, -1), which the synthesizer draws at random. Empty when the sizes disagree.
Image<int32_t> carry_field(ImageView<const int32_t> previous,
                           const temporal::AdvectionField& field);

// The layer's guides whose change along the advection means the painting's answer changed: all
// but the normals, which turn with every rotation of the camera or the surface; stacked, each
// value clamped to [0, 1]. Empty when the layer has none.
Image<float> change_guides(const Layer& layer, ImageView<const float> passes);

// carry_field(), made coherent over `coherence_radius` (temporal::coherent_field), with the
// entries dropped where the temporal guide has no `confidence`: drawn afresh
// (TemporalSpec::reseed), or, when `fresh` (the tone anchor's field at full size) is not empty,
// taken from it.
Image<int32_t> warm_field(const Layer& layer, ImageView<const int32_t> previous,
                          const temporal::AdvectionField& field, const Image<float>& confidence,
                          const Image<int32_t>& fresh, int coherence_radius = 0);

// The main transfer's schedule with a warm start, unless the layer sets its own counts.
void warm_schedule(const SynthSpec& s, const TemporalSpec& t, synth::Params& p);

}  // namespace emaki::pipeline
