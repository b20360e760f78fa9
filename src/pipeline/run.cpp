#include "pipeline/run.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>

#include "composite/composite.h"
#include "core/error.h"
#include "core/fnv.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/shot_keys.h"
#include "pipeline/ink_ratio.h"
#include "pipeline/qa_maps.h"
#include "pipeline/temporal_guide.h"
#include "pipeline/tone_anchor.h"
#include "render/passes.h"
#include "synth/synthesizer.h"
#include "temporal/advection.h"
#include "temporal/guide_change.h"

namespace emaki::pipeline {

namespace {

using Clock = std::chrono::steady_clock;

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

// A layer's result at one frame: its value and, for a temporal layer, the field that made it
// (the next frame's warm start).
struct LayerFrame {
  Image<float> value;
  Image<int32_t> nnf;
  Image<float> error;       // when asked: the synthesis error (synth::Result::error)
  Image<float> confidence;  // at a temporal frame: the temporal guide's, else empty
};

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

void add_temporal_guide(const PreparedLayer& p, ImageView<const float> passes,
                        const Image<float>& mask, int frame, const Image<float>& previous,
                        const Image<float>& previous_passes, AdvectionFields* fields,
                        TemporalPair& t, synth::Inputs& inputs) {
  const Layer& l = *p.layer;
  const bool kept = keeps_temporal_pair(l);
  t.advected =
      advect_layer(l, passes, mask, previous.cview(), previous_passes.cview(), frame, fields, kept);
  if (!kept) return;
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

// One layer at one frame. `previous`: B'(t-1) of this layer and the passes of t-1, when the
// temporal chain continues; `previous_nnf`: the field of t-1 (empty: none, the whole pyramid
// runs). `fields`: the frame's advection fields, shared by its layers. `o`: the run's error
// maps and cancel hook, if any.
LayerFrame synthesize_layer(const PreparedLayer& p, ImageView<const float> passes, int frame,
                            const Image<float>* previous, const Image<float>* previous_passes,
                            ImageView<const int32_t> previous_nnf, AdvectionFields* fields,
                            const RunOptions* o = nullptr) {
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
  if (previous && previous_passes)
    add_temporal_guide(p, passes, mask, frame, *previous, *previous_passes, fields, temporal_pair,
                       inputs);
  if (!mask.empty()) inputs.target_mask = mask.cview();
  synth::Params params = synth_params(l.synth, frame_seed(l, frame, 0));
  if (o) params.cancel = o->cancel;
  const bool chained = previous && previous_passes;
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

std::vector<const Layer*> selected_layers(const Shot& shot, const std::vector<std::string>& names) {
  std::vector<const Layer*> out;
  if (names.empty()) {
    for (const Layer& l : shot.layers) out.push_back(&l);
    return out;
  }
  for (const std::string& n : names) {
    const Layer* l = shot.find_layer(n);
    if (!l) {
      std::string known;
      for (const Layer& k : shot.layers) known += (known.empty() ? "" : ", ") + k.name;
      throw Error(Error::Field{"layers"},
                  fmt::format("no layer '{}' in the shot (layers: {})", n, known));
    }
    if (std::find(out.begin(), out.end(), l) == out.end()) out.push_back(l);
  }
  return out;
}

void resolve_range(const Shot& shot, const RunOptions& o, int& a, int& b) {
  a = o.first_frame < 0 ? shot.source.first_frame : o.first_frame;
  b = o.last_frame < 0 ? shot.source.last_frame : o.last_frame;
  if (a > b) throw Error(Error::Field{"frames"}, fmt::format("the range {}-{} is reversed", a, b));
  if (a < shot.source.first_frame || b > shot.source.last_frame)
    throw Error(Error::Field{"frames"},
                fmt::format("{}-{} leaves the shot's frames {}-{}", a, b, shot.source.first_frame,
                            shot.source.last_frame));
}

}  // namespace

namespace {

// A layer's value (or a frame's passes) at one frame, kept for the next frame's temporal chain.
struct Held {
  int frame = -1;
  Image<float> value;
  Image<int32_t> nnf;  // a temporal layer's field (the next frame's warm start), or empty
};

// One run_shot call over frames a..b of the selected layers, and what it carries from each
// frame to the next: every layer's last value and the last frame's passes.
class ShotRun {
 public:
  ShotRun(const Shot& shot, const FrameSource& frames,
          const std::map<std::string, ExemplarImages>& exemplars, const CompositeInputs& ci,
          Store& store, const RunOptions& o, const WeightMapImages& maps)
      : shot_(shot), frames_(frames), ci_(ci), store_(store), o_(o) {
    resolve_range(shot, o, a_, b_);
    selected_ = selected_layers(shot, o.layers);
    for (const Layer* l : selected_)
      prepared_.push_back(
          prepare(*l, exemplars.at(l->exemplar), maps, shot.source.width, shot.source.height));
    first_ = o.chain_from < 0 ? shot.source.first_frame
                              : std::clamp(o.chain_from, shot.source.first_frame, a_);
    // A chain from chain_from (a look-dev preview) ends with the run: its ink pin blends toward
    // no refresh frame after it, which would cost a fresh transfer of a frame it does not make.
    chain_last_ = o.chain_from < 0 ? shot.source.last_frame : b_;
  }

  RunReport run() {
    const int start = chain_start();
    report_.first_frame = start;
    report_.last_frame = b_;
    for (int f = start; f <= b_; ++f)
      for (const Layer* l : selected_) total_ += needs(*l, f) ? 1 : 0;
    t0_ = Clock::now();
    const StageScope stage(o_.stages, StageClock::kLayers);
    held_.resize(prepared_.size());
    ink_pins_.assign(prepared_.size(), {});
    for (int f = start; f <= b_; ++f) {
      std::vector<Held> now(prepared_.size());
      const bool changed = synthesize_frame(f, now);
      if (o_.composite && f >= a_ && (changed || o_.force || !store_.has_frame(f)))
        composite(f, now);
      for (std::size_t i = 0; i < prepared_.size(); ++i) held_[i] = std::move(now[i]);
      if (passes_) prev_passes_ = {f, std::move(*passes_), {}};
      passes_.reset();
    }
    drop_older_fields();
    return report_;
  }

 private:
  bool needs(const Layer& l, int f) const {
    return (o_.force && f >= a_) || !store_.has_layer(l, f);
  }
  // Whether `l` at frame f is made from its frame f - 1 (the temporal guide, the warm start).
  bool continues_chain(const Layer& l, int f) const { return l.temporal.enabled && f > first_; }

  // With temporal_fields = "last" a layer keeps one field: the last finished frame's, what a
  // resumed run starts from. The loop above drops f - 1's as it goes; this also drops what a
  // forced range, or an earlier run with "every", left behind.
  void drop_older_fields() {
    const int last = shot_.source.last_frame;
    for (const Layer* l : selected_) {
      if (!l->temporal.enabled || !l->temporal.warm_start || l->temporal.keep_every_field) continue;
      int keep = last;
      while (keep >= first_ && !store_.has_layer(*l, keep)) --keep;
      for (int f = first_; f <= last; ++f)
        if (f != keep) store_.remove_field(*l, f);
    }
  }

  // The temporal chain continues from the last finished frame: start where the frame before
  // is available.
  int chain_start() const {
    int start = a_;
    for (const Layer* l : selected_)
      if (l->temporal.enabled) {
        int s = a_;
        while (s > first_ && !store_.has_layer(*l, s - 1)) --s;
        start = std::min(start, s);
      }
    return start;
  }

  void tick(int f, const std::string& layer) const {
    if (!o_.progress) return;
    Progress p;
    p.frame = f;
    p.layer = layer;
    p.done = report_.synthesized;
    p.total = total_;
    p.elapsed_s = std::chrono::duration<double>(Clock::now() - t0_).count();
    o_.progress(p);
  }

  // Frame f's passes, read on first use: a frame whose layers are all finished needs none.
  const Image<float>& passes(int f) {
    if (!passes_) passes_ = read_passes(f);
    return *passes_;
  }
  Image<float> read_passes(int f) const {
    const StageScope stage(o_.stages, StageClock::kPasses);
    return frames_.passes(f);
  }

  // What a layer frame f needs is made from: its value and field at f - 1 when it continues its
  // chain there.
  struct Job {
    std::size_t i = 0;  // into prepared_
    const Image<float>* previous = nullptr;
    const Image<float>* previous_passes = nullptr;
    ImageView<const int32_t> previous_nnf;
  };

  // The layers frame f still needs, with what they are made from (read if not held); the others
  // count as reused.
  std::vector<Job> jobs_of(int f, std::vector<Held>& now) {
    std::vector<Job> jobs;
    for (std::size_t i = 0; i < prepared_.size(); ++i) {
      const Layer& l = *prepared_[i].layer;
      now[i].frame = f;
      if (!needs(l, f)) {
        ++report_.reused;
        continue;
      }
      Job j;
      j.i = i;
      if (continues_chain(l, f)) {
        if (held_[i].frame != f - 1 || held_[i].value.empty()) {
          held_[i].frame = f - 1;
          held_[i].value = store_.read_layer(l, f - 1);
          held_[i].nnf = l.temporal.warm_start
                             ? store_.read_field(l, f - 1, value_digest(held_[i].value.cview()))
                             : Image<int32_t>();
        }
        if (prev_passes_.frame != f - 1) prev_passes_ = {f - 1, read_passes(f - 1), {}};
        j.previous = &held_[i].value;
        j.previous_passes = &prev_passes_.value;
        j.previous_nnf = held_[i].nnf.cview();
      }
      jobs.push_back(j);
    }
    return jobs;
  }

  // Synthesizes the layers frame f still needs into `now` (parallel to prepared_); the others
  // are read lazily, only if the chain or the composite needs them. True if any was.
  bool synthesize_frame(int f, std::vector<Held>& now) {
    // The fields the farm's passes task made ahead are read only when a layer advects.
    AdvectionFields fields([this, f] { return frames_.kept_fields(f); }, o_.stages);
    const std::vector<Job> jobs = jobs_of(f, now);
    const auto synthesize = [&](const Job& j) {
      return synthesize_layer(prepared_[j.i], passes(f).cview(), f, j.previous, j.previous_passes,
                              j.previous_nnf, &fields, &o_);
    };
    std::vector<std::optional<LayerFrame>> made(prepared_.size());
    if (o_.concurrent_layers && jobs.size() >= 2) {
      for (const Job& j : jobs) tick(f, prepared_[j.i].layer->name);
      // The advection fields first, on every thread (and charged to the stage clock here): the
      // layers then only read them. A thread waiting inside its layer starts no other one.
      const ImageView<const float> p = passes(f).cview();
      for (const Job& j : jobs)
        if (j.previous) fields.prepare(*prepared_[j.i].layer, j.previous_passes->cview(), p, f);
      parallel_for(int64_t(jobs.size()), 1, [&](int64_t a, int64_t b) {
        for (int64_t k = a; k < b; ++k)
          isolated([&] { made[jobs[std::size_t(k)].i] = synthesize(jobs[std::size_t(k)]); });
      });
    }
    for (const Job& j : jobs) {
      const std::size_t i = j.i;
      const Layer& l = *prepared_[i].layer;
      if (!made[i]) tick(f, l.name);
      LayerFrame r = made[i] ? std::move(*made[i]) : synthesize(j);
      if (l.temporal.ink_ratio > 0.0f)
        ink_pins_[i].pin(l.temporal, first_, chain_last_, f, j.previous != nullptr,
                         prepared_[i].value_channels, passes(f).cview(), r.value, r.confidence,
                         [&](int k) { return measured_ink(i, k, f); });
      if (!r.error.empty())
        store_.write_qa_map("error", l, f,
                            synthesis_error_map(r.error.cview(), r.value.cview(),
                                                prepared_[i].value_channels, l.synth.patch_size)
                                .cview());
      now[i].value = std::move(r.value);
      now[i].nnf = std::move(r.nnf);
      if (!now[i].nnf.empty())
        store_.write_field(l, f, now[i].nnf.cview(), value_digest(now[i].value.cview()));
      note_stale_chain(l, f, now[i].value.cview());
      store_.write_layer(l, f, now[i].value.cview());
      // Frame f is finished: with only the last field kept, f - 1's is no longer needed (also
      // when f made none, its mask being empty: a resume from f then starts cold either way).
      if (l.temporal.enabled && l.temporal.warm_start && !l.temporal.keep_every_field && f > first_)
        store_.remove_field(l, f - 1);
      ++report_.synthesized;
    }
    return !jobs.empty();
  }

  // TemporalSpec::ink_refresh: the reference measured on a fresh transfer of layer i's frame r,
  // a frame ink_reference_frame() names (the same in a resumed run or a farm chunk), with the
  // current frame f's passes or r's read.
  InkReference measured_ink(std::size_t i, int r, int f) {
    const Image<float> other = r == f ? Image<float>() : read_passes(r);
    const ImageView<const float> p = r == f ? passes(f).cview() : other.cview();
    AdvectionFields none;
    RunOptions measured_only = o_;  // cancellable, but no error map: the result is only measured
    measured_only.error_maps = false;
    const LayerFrame fresh =
        synthesize_layer(prepared_[i], p, r, nullptr, nullptr, {}, &none, &measured_only);
    InkReference ref = ink_reference(prepared_[i].layer->temporal, fresh.value.cview(),
                                     prepared_[i].value_channels, p);
    ref.frame = r;
    return ref;
  }

  // Before a forced run's last frame f of a temporal layer replaces the finished one: when the
  // next frame is finished too and the new value differs from the old, the finished frames after
  // f were made from the old one (RunReport::stale). An unreadable old frame counts as different.
  void note_stale_chain(const Layer& l, int f, ImageView<const float> value) {
    const int last = shot_.source.last_frame;
    if (!o_.force || f != b_ || !l.temporal.enabled || f >= last || !store_.has_layer(l, f) ||
        !store_.has_layer(l, f + 1))
      return;
    try {
      if (value_digest(store_.read_layer(l, f).cview()) == value_digest(value)) return;
    } catch (const Error&) {
    }
    int c = f + 1;
    while (c < last && store_.has_layer(l, c + 1)) ++c;
    report_.stale.push_back({l.name, f + 1, c});
  }

  // Composites frame f from every layer of the shot: this frame's new values, else the stored
  // ones. A layer left out with --layers that was never synthesized leaves the frame alone.
  void composite(int f, const std::vector<Held>& now) {
    const StageScope stage(o_.stages, StageClock::kComposite);
    std::vector<Image<float>> read_back;
    read_back.reserve(shot_.layers.size());  // views point into it: no reallocation
    std::vector<ImageView<const float>> views;
    for (const Layer& l : shot_.layers) {
      const auto it = std::find_if(prepared_.begin(), prepared_.end(),
                                   [&](const PreparedLayer& p) { return p.layer == &l; });
      if (it != prepared_.end() && !now[it - prepared_.begin()].value.empty()) {
        views.push_back(now[it - prepared_.begin()].value.cview());
      } else if (store_.has_layer(l, f)) {
        read_back.push_back(store_.read_layer(l, f));
        views.push_back(read_back.back().cview());
      } else {
        return;
      }
    }
    tick(f, "");
    const ImageView<const float> p = passes(f).cview();
    const Image<float> comp = composite_frame(shot_, p, views, ci_);
    store_.write_frame(f, comp.cview(), views, p);
    ++report_.composited;
  }

  const Shot& shot_;
  const FrameSource& frames_;
  const CompositeInputs& ci_;
  Store& store_;
  const RunOptions& o_;
  int a_ = 0, b_ = 0;   // the requested frames
  int first_ = 0;       // the shot's first frame
  int chain_last_ = 0;  // the last frame the chain may reach (TemporalSpec::ink_blend)
  std::vector<const Layer*> selected_;
  std::vector<PreparedLayer> prepared_;  // parallel to selected_
  RunReport report_;
  int total_ = 0;  // layer-frames to synthesize
  Clock::time_point t0_;
  std::vector<Held> held_;        // parallel to prepared_: each layer's last value
  std::vector<InkPin> ink_pins_;  // parallel to prepared_ (TemporalSpec::ink_ratio)
  Held prev_passes_;
  std::optional<Image<float>> passes_;  // the current frame's, once read
};

}  // namespace

uint64_t value_digest(ImageView<const float> value) {
  // FNV-1a, 64-bit, over 32-bit words: the size, then every sample's bit pattern.
  uint64_t h = kFnvOffset;
  auto add = [&h](uint32_t w) { h = fnv1a_add(h, w); };
  add(uint32_t(value.width)), add(uint32_t(value.height)), add(uint32_t(value.channels));
  for (int y = 0; y < value.height; ++y)
    for (int i = 0; i < value.width * value.channels; ++i)
      add(std::bit_cast<uint32_t>(value.row(y)[i]));
  return h;
}

RunReport run_shot(const Shot& shot, const FrameSource& frames,
                   const std::map<std::string, ExemplarImages>& exemplars,
                   const CompositeInputs& ci, Store& store, const RunOptions& o,
                   const WeightMapImages& weight_maps) {
  return ShotRun(shot, frames, exemplars, ci, store, o, weight_maps).run();
}

Image<float> synthesize_alone(const Layer& layer, const ExemplarImages& exemplar,
                              ImageView<const float> passes, int frame,
                              const WeightMapImages& weight_maps) {
  return synthesize_layer(prepare(layer, exemplar, weight_maps, passes.width, passes.height),
                          passes, frame, nullptr, nullptr, {}, nullptr)
      .value;
}

int recomposite(const Shot& shot, const FrameSource& frames, const CompositeInputs& ci,
                Store& store, const RunOptions& o) {
  int a = 0, b = 0;
  resolve_range(shot, o, a, b);
  int written = 0;
  for (int f = a; f <= b; ++f) {
    std::vector<Image<float>> values;
    for (const Layer& l : shot.layers) {
      if (!store.has_layer(l, f))
        throw Error(
            shot_keys::layer(l.name),
            fmt::format("frame {} has not been synthesized yet (run `emaki run` first)", f));
      values.push_back(store.read_layer(l, f));
    }
    std::vector<ImageView<const float>> views;
    for (const Image<float>& v : values) views.push_back(v.cview());
    const Image<float> passes = frames.passes(f);
    if (o.progress) {
      Progress p;
      p.frame = f;
      p.done = f - a;
      p.total = b - a + 1;
      o.progress(p);
    }
    const Image<float> comp = composite_frame(shot, passes.cview(), views, ci);
    store.write_frame(f, comp.cview(), views, passes.cview());
    ++written;
  }
  return written;
}

void check_run_options(const Shot& shot, const RunOptions& options) {
  int a = 0, b = 0;
  resolve_range(shot, options, a, b);
  (void)selected_layers(shot, options.layers);
}

}  // namespace emaki::pipeline
