#include "pipeline/run.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <optional>

#include "core/error.h"
#include "core/fnv.h"
#include "core/parallel.h"
#include "core/shot_keys.h"
#include "pipeline/ink_ratio.h"
#include "pipeline/layer_frame.h"
#include "pipeline/qa_maps.h"
#include "pipeline/temporal_guide.h"
#include "render/passes.h"
#include "temporal/advection.h"

namespace emaki::pipeline {

namespace {

using Clock = std::chrono::steady_clock;
using detail::advect_previous;
using detail::LayerFrame;
using detail::prepare;
using detail::PreparedLayer;
using detail::synthesize_layer;

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
    bool chained = false;
    temporal::Advection advected;  // chained: B'(t-1) carried to t
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
        j.chained = true;
        j.previous_nnf = held_[i].nnf.cview();
      }
      jobs.push_back(std::move(j));
    }
    return jobs;
  }

  // B'(t-1) of the chained jobs carried to frame f, all before any is synthesized; then what only
  // the advection reads is let go (the passes of f - 1, the values B'(t-1), all but the nnf of
  // the advection fields): a frame's synthesis holds its own passes and the warm starts' fields.
  void advect_jobs(int f, std::vector<Job>& jobs, AdvectionFields& fields) {
    if (std::none_of(jobs.begin(), jobs.end(), [](const Job& j) { return j.chained; })) return;
    if (prev_passes_.frame != f - 1) prev_passes_ = {f - 1, read_passes(f - 1), {}};
    for (Job& j : jobs)
      if (j.chained) {
        j.advected = advect_previous(prepared_[j.i], passes(f).cview(), f, held_[j.i].value,
                                     prev_passes_.value.cview(), &fields);
        held_[j.i].value = {};
      }
    prev_passes_ = {};
    fields.keep_only_warm_start_fields();
  }

  // Synthesizes the layers frame f still needs into `now` (parallel to prepared_); the others
  // are read lazily, only if the chain or the composite needs them. True if any was.
  bool synthesize_frame(int f, std::vector<Held>& now) {
    // The fields the farm's passes task made ahead are read only when a layer advects.
    AdvectionFields fields([this, f] { return frames_.kept_fields(f); }, o_.stages);
    std::vector<Job> jobs = jobs_of(f, now);
    if (jobs.empty()) return false;
    const bool together = o_.concurrent_layers && jobs.size() >= 2;
    for (std::size_t k = 0; k < (together ? jobs.size() : 1); ++k)
      tick(f, prepared_[jobs[k].i].layer->name);
    advect_jobs(f, jobs, fields);
    const auto synthesize = [&, p = passes(f).cview()](Job& j) {  // the passes read here, once
      return synthesize_layer(prepared_[j.i], p, f, j.chained ? &j.advected : nullptr,
                              j.previous_nnf, &fields, &o_);
    };
    std::vector<std::optional<LayerFrame>> made(prepared_.size());
    if (together)  // a thread waiting inside its layer starts no other one
      parallel_for(int64_t(jobs.size()), 1, [&](int64_t a, int64_t b) {
        for (int64_t k = a; k < b; ++k)
          isolated([&] { made[jobs[std::size_t(k)].i] = synthesize(jobs[std::size_t(k)]); });
      });
    for (Job& j : jobs) {
      const std::size_t i = j.i;
      const Layer& l = *prepared_[i].layer;
      if (!together && &j != &jobs.front()) tick(f, l.name);
      LayerFrame r = made[i] ? std::move(*made[i]) : synthesize(j);
      if (l.temporal.ink_ratio > 0.0f)
        ink_pins_[i].pin(l.temporal, first_, chain_last_, f, j.chained, prepared_[i].value_channels,
                         passes(f).cview(), r.value, r.confidence,
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
    return true;
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
        synthesize_layer(prepared_[i], p, r, nullptr, {}, &none, &measured_only);
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
                          passes, frame, nullptr, {}, nullptr)
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
