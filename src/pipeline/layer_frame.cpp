#include "pipeline/layer_frame.h"

#include <algorithm>

#include "composite/composite.h"
#include "core/error.h"
#include "core/shot_keys.h"
#include "pipeline/ink_ratio.h"
#include "render/passes.h"
#include "synth/synthesizer.h"
#include "temporal/guide_change.h"

namespace emaki::pipeline::detail {

PreparedLayer prepare(const Layer& layer, const ExemplarImages& ex, const WeightMapImages& maps,
                      int frame_width, int frame_height) {
  PreparedLayer p;
  p.layer = &layer;
  p.value_channels = layer.single_colour ? 1 : 3;
  if (layer.single_colour) {
    p.style = composite::touch(ex.painting.cview(), layer.channel);
  } else {
    if (ex.painting.channels() < 3)
      throw Error(shot_keys::layer_key(layer.name, shot_keys::kSingleColour),
                  "false needs an RGB painting, its exemplar's painting is grey");
    p.style = extract(ex.painting.cview(), 0, 3);
  }
  for (const GuideSpec& g : layer.guides) {
    const auto cut = ex.guides.find(g.pass);
    p.source_guides.push_back(
        cut != ex.guides.end()
            ? cut->second
            : std::make_shared<const Image<float>>(extract_pass(ex.passes.cview(), g.pass)));
    const auto it = g.map_image.empty() ? maps.end() : maps.find(g.map_image);
    CHECK(g.map_image.empty() || it != maps.end());  // shot::load_weight_maps read every one
    p.painted_maps.push_back(it == maps.end() ? nullptr : &it->second);
  }
  p.sharpening = temporal_sharpening(layer.temporal, frame_width, frame_height, p.style.width(),
                                     p.style.height());
  if (layer.temporal.enabled && p.sharpening.guide_sigma > 0.0f)
    p.temporal_style = temporal::low_pass(p.style.cview(), p.sharpening.guide_sigma);
  if (layer.temporal.enabled && layer.temporal.anchor > 0) {
    std::vector<synth::Plane> sources;
    for (const auto& g : p.source_guides) sources.push_back(g->cview());
    p.anchor = anchor_exemplar(p.style.cview(), sources, layer.temporal.anchor);
  }
  return p;
}

namespace {

// The temporal guide pair of a layer at a temporal frame: B'adv and its confidence, both sides
// low-passed with guide_sigma. `target` holds what the pair's target view points into.
struct TemporalPair {
  temporal::Advection advected;
  Image<float> target;
};

// Whether the layer's temporal pair joins its main transfer. A pair of weight 0 changes no
// patch's error (its channels quantise to 0 on both sides; the other channels' weights, and with
// them the distances and errors, stay the same to the bit): it is left out, and its advection
// makes the confidence alone (the warm start's holes) — unless a guide's weight is negative
// (1 / the number of pairs, which leaving one out would change).
bool keeps_temporal_pair(const Layer& l) {
  return l.temporal.weight != 0.0f ||
         std::any_of(l.guides.begin(), l.guides.end(),
                     [](const GuideSpec& g) { return g.weight < 0.0f; });
}

void add_temporal_guide(const PreparedLayer& p, const Image<float>& mask,
                        temporal::Advection&& advected, TemporalPair& t, synth::Inputs& inputs) {
  const Layer& l = *p.layer;
  t.advected = std::move(advected);
  if (!keeps_temporal_pair(l)) return;
  const bool low = p.sharpening.guide_sigma > 0.0f;
  if (low)
    t.target = temporal::low_pass(t.advected.value.cview(), p.sharpening.guide_sigma,
                                  mask.empty() ? ImageView<const float>{} : mask.cview());
  synth::GuidePair pair{shot_keys::layer_key(l.name, shot_keys::kTemporal),
                        low ? p.temporal_style.cview() : p.style.cview(),
                        low ? t.target.cview() : t.advected.value.cview(), l.temporal.weight};
  if (!t.advected.confidence.empty()) pair.weight_map = synth::Plane(t.advected.confidence.cview());
  inputs.guides.push_back(pair);
}

// The tone anchor at a temporal frame (TemporalSpec::anchor, pipeline/tone_anchor.h): with a
// temporal guide, its target B'adv anchored to a fresh transfer's tone (moved out of the result).
Anchor anchor_layer(const PreparedLayer& p, int frame, const synth::Params& params,
                    const Image<float>& mask, TemporalPair& t, synth::Inputs& inputs) {
  const Layer& l = *p.layer;
  const bool guide = l.temporal.weight > 0.0f;
  if (l.temporal.anchor <= 0 ||
      (!guide && !l.temporal.anchor_holes && l.temporal.ink_match <= 0.0f))
    return {};
  synth::Inputs fresh = inputs;
  if (keeps_temporal_pair(l)) fresh.guides.pop_back();
  synth::Params fresh_params = params;
  fresh_params.seed = frame_seed(l, frame, 2);
  fresh_params.finest_search_vote_iters = l.temporal.anchor_finest_iters;
  Anchor a = anchor_tone(fresh, p.anchor, fresh_params, t.advected.value.cview(), p.value_channels,
                         mask, l.temporal.anchor_sigma, l.temporal.anchor_rate);
  if (guide && !a.target.empty()) {
    t.target = std::move(a.target);
    inputs.guides.back().target = synth::Plane(t.target.cview());
  }
  if (!l.temporal.anchor_holes) a.nnf = {};
  return a;
}

}  // namespace

// B'(t-1) of layer `p` carried to `frame` (advect_layer with the layer's mask and whether it
// keeps the temporal pair): what its synthesis at `frame` takes from frame - 1 and its passes.
temporal::Advection advect_previous(const PreparedLayer& p, ImageView<const float> passes,
                                    int frame, const Image<float>& previous,
                                    ImageView<const float> previous_passes,
                                    AdvectionFields* fields) {
  const Layer& l = *p.layer;
  return advect_layer(l, passes, layer_mask(passes, l.mask), previous.cview(), previous_passes,
                      frame, fields, keeps_temporal_pair(l));
}

// One layer at one frame. `advected_in`: when the temporal chain continues, B'(t-1) of this layer
// carried to t (advect_previous(), taken); `previous_nnf`: the field of t-1 (empty: none, the
// whole pyramid runs). `fields`: the frame's advection fields, shared by its layers. `o`: the
// run's error maps and cancel hook, if any.
LayerFrame synthesize_layer(const PreparedLayer& p, ImageView<const float> passes, int frame,
                            temporal::Advection* advected_in, ImageView<const int32_t> previous_nnf,
                            AdvectionFields* fields, const RunOptions* o) {
  const Layer& l = *p.layer;
  const Image<float> mask = layer_mask(passes, l.mask);
  const int n = p.value_channels;
  if (!mask.empty()) {
    bool any = false;
    for (int y = 0; y < mask.height() && !any; ++y)
      for (int x = 0; x < mask.width() && !any; ++x) any = mask(x, y) > 0.5f;
    if (!any)  // nothing to synthesize: transparent, and no field
      return {Image<float>(passes.width, passes.height, n + 1), {}, {}, {}};
  }
  std::vector<Image<float>> targets, pass_maps;
  targets.reserve(l.guides.size());  // views point into them: no reallocation
  pass_maps.reserve(l.guides.size());
  synth::Inputs inputs;
  inputs.style = p.style.cview();
  inputs.style_name = shot_keys::exemplar_key(l.exemplar, shot_keys::kPainting);
  for (std::size_t i = 0; i < l.guides.size(); ++i) {
    const GuideSpec& g = l.guides[i];
    targets.push_back(extract_pass(passes, g.pass));
    synth::GuidePair pair{shot_keys::layer_guide(l.name, g.pass), p.source_guides[i]->cview(),
                          targets.back().cview(), g.weight};
    if (!g.map_pass.empty()) {
      pass_maps.push_back(extract_pass(passes, g.map_pass));
      pair.weight_map = synth::Plane(pass_maps.back().cview());
    } else if (p.painted_maps[i]) {
      pair.weight_map = synth::Plane(p.painted_maps[i]->cview());
      pair.weight_map_name = g.map_image;
    }
    inputs.guides.push_back(pair);
  }
  TemporalPair temporal_pair;
  const temporal::Advection& advected = temporal_pair.advected;
  const bool chained = advected_in != nullptr;
  if (chained) add_temporal_guide(p, mask, std::move(*advected_in), temporal_pair, inputs);
  if (!mask.empty()) inputs.target_mask = mask.cview();
  synth::Params params = synth_params(l.synth, frame_seed(l, frame, 0));
  if (o) params.cancel = o->cancel;
  const Anchor anchor =
      chained ? anchor_layer(p, frame, params, mask, temporal_pair, inputs) : Anchor{};
  // With a temporal guide, B'adv carries the previous frame's converged texture: one search-vote
  // iteration at the finest level instead of two keeps flicker and the judge's style energy
  // within their bars (docs/design/advection.md) and saves a quarter of the time per frame.
  Image<int32_t> warm;
  Image<float> uniformity_map;
  if (chained) {
    params.finest_search_vote_iters = l.temporal.finest_iters;
    const temporal::AdvectionField* field = fields ? fields->find(l, frame) : nullptr;
    if (l.temporal.warm_start && field && !previous_nnf.empty()) {
      warm = warm_field(l, previous_nnf, *field, advected.confidence, anchor.nnf,
                        p.sharpening.coherence_radius);
      params.initial_nnf = warm.cview();
      params.warm_sharp_estimate = p.sharpening.sharp_estimate;
      warm_schedule(l.synth, l.temporal, params);
    }
    temporal_uniformity(l.temporal, targets, mask, params, uniformity_map);
  }
  synth::OutputRequest request;
  request.nnf = l.temporal.enabled && l.temporal.warm_start;
  request.error = o && o->error_maps;  // measured once the result is made: it does not change it
  synth::Result r = synth::synthesize(inputs, params, request);
  match_ink(r.image, n, anchor, mask, advected.confidence, l.temporal.ink_sigma,
            l.temporal.ink_match);
  return {std::move(r.image), std::move(r.nnf), std::move(r.error),
          std::move(temporal_pair.advected.confidence)};
}

}  // namespace emaki::pipeline::detail
