#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <ctime>
#include <map>

#include "core/error.h"
#include "pipeline/flicker.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "render/passes.h"
#include "synth/synthesizer.h"

namespace emaki::pipeline {
namespace {

// Synthetic passes: a covered frame whose normal and diffuse vary smoothly, a line down the
// middle, the whole picture sliding right by one pixel a frame (motion says so).
class SlidingFrames : public FrameSource {
 public:
  SlidingFrames(int w, int h) : w_(w), h_(h) {}
  Image<float> passes(int frame) const override {
    ++calls;
    Image<float> p(w_, h_, render::kChannelCount);
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        float* o = p.at(x, y);
        const float u = float(x - frame) / w_, v = float(y) / h_;
        o[render::kNormal] = u;
        o[render::kNormal + 1] = v;
        o[render::kNormal + 2] = 0.5f;
        for (int c = 0; c < 3; ++c)
          o[render::kPositionNorm + c] = o[render::kRestPosition + c] = c == 0   ? u
                                                                        : c == 1 ? v
                                                                                 : 0.5f;
        o[render::kDiffuse] = 0.5f + 0.5f * std::sin(6.0f * u);
        o[render::kAlbedo] = o[render::kAlbedo + 1] = o[render::kAlbedo + 2] = 0.5f;
        o[render::kObjectId] = 2.0f;
        o[render::kAlpha] = 1.0f;
        o[render::kOutline] = x - frame == w_ / 2 ? 1.0f : 0.0f;
        o[render::kMotion] = -1.0f;  // the previous frame had this point one pixel to the left
      }
    return p;
  }
  mutable int calls = 0;

 private:
  int w_, h_;
};

class MemoryStore : public Store {
 public:
  bool has_layer(const Layer& l, int f) const override { return layers.count({l.name, f}) > 0; }
  Image<float> read_layer(const Layer& l, int f) const override {
    ++reads;
    return layers.at({l.name, f}).clone();
  }
  void write_layer(const Layer& l, int f, ImageView<const float> v) override {
    Image<float> img(v.width, v.height, v.channels);
    for (int y = 0; y < v.height; ++y)
      std::memcpy(img.row(y), v.row(y), sizeof(float) * v.width * v.channels);
    layers[{l.name, f}] = std::move(img);
  }
  void write_field(const Layer& l, int f, ImageView<const int32_t> nnf, uint64_t digest) override {
    Image<int32_t> img(nnf.width, nnf.height, 2);
    for (int y = 0; y < nnf.height; ++y)
      std::memcpy(img.row(y), nnf.row(y), sizeof(int32_t) * 2 * nnf.width);
    fields[{l.name, f}] = {digest, std::move(img)};
  }
  Image<int32_t> read_field(const Layer& l, int f, uint64_t digest) const override {
    const auto it = fields.find({l.name, f});
    if (it == fields.end() || it->second.first != digest) return {};
    return it->second.second.clone();
  }
  bool has_frame(int f) const override { return frames.count(f) > 0; }
  void write_frame(int f, ImageView<const float> c, const std::vector<ImageView<const float>>&,
                   ImageView<const float>) override {
    frames[f] = c(c.width / 2, c.height / 2, 0);
  }
  std::map<std::pair<std::string, int>, Image<float>> layers;
  std::map<std::pair<std::string, int>, std::pair<uint64_t, Image<int32_t>>> fields;
  std::map<int, float> frames;
  mutable int reads = 0;
};

bool same_layer(const MemoryStore& a, const MemoryStore& b, int f) {
  const Image<float>& x = a.layers.at({"base", f});
  const Image<float>& y = b.layers.at({"base", f});
  return x.bytes() == y.bytes() && std::memcmp(x.row(0), y.row(0), x.bytes()) == 0;
}

Shot tiny_shot() {
  Shot s;
  s.source.first_frame = 0;
  s.source.last_frame = 3;
  s.source.width = 40;
  s.source.height = 30;
  Exemplar e;
  e.name = "ex";
  s.exemplars.push_back(e);
  Layer l;
  l.name = "base";
  l.exemplar = "ex";
  l.guides = {{"normal", 1.0f}, {"diffuse", 1.0f}};
  l.synth.patch_size = 3;
  s.layers.push_back(l);
  return s;
}

std::map<std::string, ExemplarImages> tiny_exemplar() {
  const SlidingFrames f(36, 28);
  ExemplarImages ex;
  ex.passes = f.passes(0);
  ex.painting = Image<float>(36, 28, 3);
  for (int y = 0; y < 28; ++y)
    for (int x = 0; x < 36; ++x)
      for (int c = 0; c < 3; ++c)
        ex.painting(x, y, c) = 0.5f + 0.4f * std::sin(0.9f * x + 0.4f * y + c);
  std::map<std::string, ExemplarImages> m;
  m.emplace("ex", std::move(ex));
  return m;
}

TEST(Pipeline, LineMaskIsDilated) {
  const SlidingFrames f(40, 30);
  const Image<float> p = f.passes(0);
  const Image<float> m = layer_mask(p.cview(), {MaskKind::kLines, 2.0f, 0.5f});
  EXPECT_EQ(m(20, 10), 1.0f);
  EXPECT_EQ(m(22, 10), 1.0f);
  EXPECT_EQ(m(23, 10), 0.0f);
  EXPECT_TRUE(layer_mask(p.cview(), {MaskKind::kNone, 0.0f, 0.5f}).empty());
}

// The dilation is a disc: every pixel within `radius` of a line pixel, and no other.
TEST(Pipeline, MaskDilationIsADisc) {
  const int w = 37, h = 29;
  Image<float> p(w, h, render::kChannelCount);
  std::vector<std::pair<int, int>> lines = {{3, 4}, {18, 14}, {35, 27}, {0, 28}, {20, 15}};
  for (auto [x, y] : lines) p(x, y, render::kOutline) = 1.0f;
  for (float radius : {1.0f, 1.5f, 2.0f, 3.3f}) {
    const Image<float> m = layer_mask(p.cview(), {MaskKind::kLines, radius, 0.5f});
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        bool near = false;
        for (auto [lx, ly] : lines)
          near |= float((x - lx) * (x - lx) + (y - ly) * (y - ly)) <= radius * radius;
        ASSERT_EQ(m(x, y), near ? 1.0f : 0.0f) << x << "," << y << " radius " << radius;
      }
  }
}

TEST(Pipeline, FlickerFollowsMotion) {
  const SlidingFrames f(40, 30);
  const Image<float> p0 = f.passes(0), p1 = f.passes(1);
  // A value glued to the surface (a function of u) does not flicker when followed by motion.
  Image<float> v0(40, 30, 1), v1(40, 30, 1), still(40, 30, 1);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) {
      v0(x, y) = p0(x, y, render::kNormal);
      v1(x, y) = p1(x, y, render::kNormal);
      still(x, y) = 0.3f;
    }
  const FrameFlicker glued = frame_flicker(v1.cview(), v0.cview(), p1.cview(), p0.cview(), -1);
  EXPECT_GT(glued.objects.pixels, 800);
  EXPECT_NEAR(glued.objects.mean(), 0.0, 1e-6);
  // The same value not moving with the surface does flicker: one pixel's worth of u.
  const FrameFlicker slid = frame_flicker(v0.cview(), v0.cview(), p1.cview(), p0.cview(), -1);
  EXPECT_NEAR(slid.objects.mean(), 1.0 / 40, 1e-4);
  EXPECT_EQ(glued.ground.pixels, 0);
}

// Per object id: the left part of the frame (object 2) carries a value glued to the surface, the
// right part (object 5) one that stands still while the surface slides; only 5 flickers, and a
// sequence averages each id over the frames it was measured in.
TEST(Pipeline, FlickerBreaksDownByObjectId) {
  const SlidingFrames f(40, 30);
  Image<float> p0 = f.passes(0), p1 = f.passes(1);
  Image<float> v0(40, 30, 1), v1(40, 30, 1);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x) {
      const bool right = x >= 24;
      p0(x, y, render::kObjectId) = p1(x, y, render::kObjectId) = right ? 5.0f : 2.0f;
      v0(x, y) = p0(x, y, render::kNormal);
      v1(x, y) = right ? v0(x, y) : p1(x, y, render::kNormal);
    }
  const FrameFlicker ff = frame_flicker(v1.cview(), v0.cview(), p1.cview(), p0.cview(), -1);
  ASSERT_EQ(ff.by_id.size(), 2u);
  EXPECT_GT(ff.by_id.at(2).pixels, 300);
  EXPECT_GT(ff.by_id.at(5).pixels, 300);
  EXPECT_EQ(ff.by_id.at(2).pixels + ff.by_id.at(5).pixels, ff.all.pixels);
  EXPECT_NEAR(ff.by_id.at(2).mean(), 0.0, 1e-6);
  EXPECT_NEAR(ff.by_id.at(5).mean(), 1.0 / 40, 1e-4);
  SequenceFlicker seq;
  seq.add(ff);
  FrameFlicker only_two;
  only_two.by_id[2] = {0.5, 10};
  seq.add(only_two);
  EXPECT_NEAR(seq.by_id.at(2).mean(), 0.025, 1e-6);     // (0 + 0.05) / 2 frames
  EXPECT_NEAR(seq.by_id.at(5).mean(), 1.0 / 40, 1e-4);  // measured in one frame only
  EXPECT_EQ(seq.by_id.at(5).pixels, 1);
  // A selection of the right part alone counts its pixels alone.
  Image<uint8_t> right(40, 30, 1);
  for (int y = 0; y < 30; ++y)
    for (int x = 24; x < 40; ++x) right(x, y) = 1;
  const FrameFlicker sel =
      frame_flicker(v1.cview(), v0.cview(), p1.cview(), p0.cview(), -1, nullptr, &right);
  ASSERT_EQ(sel.by_id.size(), 1u);
  EXPECT_EQ(sel.by_id.at(5).pixels, ff.by_id.at(5).pixels);
  EXPECT_NEAR(sel.all.mean(), 1.0 / 40, 1e-4);
}

TEST(Pipeline, RunsResumesAndContinuesTheChain) {
  const Shot shot = tiny_shot();
  const SlidingFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  MemoryStore full;
  RunOptions o;
  RunReport r = run_shot(shot, frames, ex, CompositeInputs{}, full, o);
  EXPECT_EQ(r.synthesized, 4);
  EXPECT_EQ(r.composited, 4);

  // Only frames 0-1 finished: resuming synthesizes 2-3 from frame 1, read back once.
  MemoryStore part;
  o.last_frame = 1;
  run_shot(shot, frames, ex, CompositeInputs{}, part, o);
  o.last_frame = -1;
  part.reads = 0;
  r = run_shot(shot, frames, ex, CompositeInputs{}, part, o);
  EXPECT_EQ(r.synthesized, 2);
  EXPECT_EQ(r.reused, 2);
  EXPECT_EQ(part.reads, 1);
  for (int f = 0; f <= 3; ++f) {
    const Image<float>& a = full.layers.at({"base", f});
    const Image<float>& b = part.layers.at({"base", f});
    ASSERT_EQ(a.bytes(), b.bytes());
    EXPECT_EQ(std::memcmp(a.row(0), b.row(0), a.bytes()), 0) << "frame " << f;
  }

  // --frames 3-3 on a fresh store starts the chain at the first frame.
  MemoryStore fresh;
  o.first_frame = 3;
  o.last_frame = 3;
  r = run_shot(shot, frames, ex, CompositeInputs{}, fresh, o);
  EXPECT_EQ(r.first_frame, 0);
  EXPECT_EQ(r.synthesized, 4);
  EXPECT_EQ(r.composited, 1);
}

// TemporalSpec::ink_refresh: the reference is re-measured on fresh transfers of frames counted
// from the chain's first, so a run resumed anywhere in the chain makes the same frames; with
// ink_blend too (each frame's reference blended between the refresh frames around it).
TEST(Pipeline, InkRefreshResumesAnywhereWithTheSameFrames) {
  Shot shot = tiny_shot();
  shot.source.last_frame = 5;
  const SlidingFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  RunOptions o;
  MemoryStore plain;
  run_shot(shot, frames, ex, CompositeInputs{}, plain, o);
  TemporalSpec& t = shot.layers[0].temporal;
  t.ink_ratio = 1.0f;
  t.ink_confident = 1.0f;
  t.ink_refresh = 2;
  MemoryStore stepped;
  for (bool blend : {false, true}) {
    SCOPED_TRACE(blend);
    t.ink_blend = blend;
    MemoryStore full;
    run_shot(shot, frames, ex, CompositeInputs{}, full, o);
    bool pinned = false, blended = false;
    for (int f = 1; f <= 5; ++f) {
      pinned = pinned || !same_layer(plain, full, f);
      blended = blended || (blend && !same_layer(stepped, full, f));
    }
    EXPECT_TRUE(pinned);
    EXPECT_EQ(blended, blend);
    for (int stop : {2, 3}) {  // resumed at a refresh frame's successor (3) and at one (4)
      MemoryStore part;
      o.last_frame = stop;
      run_shot(shot, frames, ex, CompositeInputs{}, part, o);
      o.last_frame = -1;
      EXPECT_EQ(run_shot(shot, frames, ex, CompositeInputs{}, part, o).synthesized, 5 - stop);
      for (int f = 0; f <= 5; ++f) EXPECT_TRUE(same_layer(full, part, f)) << stop << " " << f;
    }
    if (!blend) stepped = std::move(full);
  }
}

// A chain from RunOptions::chain_from (emaki lookdev --temporal) ends with the run: the blend
// has no refresh frame after it to reach for, so the frame is the one without the blend (and no
// fresh transfer of a later frame is made for it).
TEST(Pipeline, APreviewChainBlendsTowardNoLaterFrame) {
  Shot shot = tiny_shot();
  shot.source.last_frame = 5;
  const SlidingFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  TemporalSpec& t = shot.layers[0].temporal;
  t.ink_ratio = 1.0f;
  t.ink_refresh = 2;
  RunOptions o;
  o.first_frame = o.chain_from = 2;
  o.last_frame = 3;
  MemoryStore stepped, blended;
  run_shot(shot, frames, ex, CompositeInputs{}, stepped, o);
  t.ink_blend = true;
  run_shot(shot, frames, ex, CompositeInputs{}, blended, o);
  EXPECT_TRUE(same_layer(stepped, blended, 3));
}

TEST(Pipeline, WarmStartResumesFromTheStoredFieldOnly) {
  const Shot shot = tiny_shot();
  const SlidingFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  MemoryStore full;
  run_shot(shot, frames, ex, CompositeInputs{}, full, RunOptions{});
  ASSERT_EQ(full.fields.size(), 4u);  // every frame keeps its field for the next one
  EXPECT_EQ(full.fields.at({"base", 1}).first, value_digest(full.layers.at({"base", 1}).cview()));

  // Frames 0-1 finished; the resumed frame 2 starts from frame 1's stored field, as it did in
  // the uninterrupted run.
  RunOptions o;
  o.last_frame = 1;
  MemoryStore part;
  run_shot(shot, frames, ex, CompositeInputs{}, part, o);
  MemoryStore stale;  // the same, with a field that belongs to another value
  run_shot(shot, frames, ex, CompositeInputs{}, stale, o);
  stale.fields.at({"base", 1}).first ^= 1;
  o.last_frame = -1;
  run_shot(shot, frames, ex, CompositeInputs{}, part, o);
  run_shot(shot, frames, ex, CompositeInputs{}, stale, o);
  EXPECT_TRUE(same_layer(full, part, 2));
  EXPECT_TRUE(same_layer(full, part, 3));
  // A field that does not match is not used: frame 2 runs the whole pyramid (and differs).
  EXPECT_FALSE(same_layer(full, stale, 2));

  // Without the warm start every frame runs the whole pyramid: the frames after the first differ.
  Shot cold_shot = shot;
  cold_shot.layers[0].temporal.warm_start = false;
  MemoryStore cold;
  run_shot(cold_shot, frames, ex, CompositeInputs{}, cold, RunOptions{});
  EXPECT_TRUE(cold.fields.empty());
  EXPECT_TRUE(same_layer(full, cold, 0));
  EXPECT_FALSE(same_layer(full, cold, 2));
}

TEST(Pipeline, TemporalGuideChangesFramesAfterTheFirst) {
  Shot shot = tiny_shot();
  const SlidingFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  MemoryStore with, without;
  run_shot(shot, frames, ex, CompositeInputs{}, with, RunOptions{});
  shot.layers[0].temporal.enabled = false;
  run_shot(shot, frames, ex, CompositeInputs{}, without, RunOptions{});
  const auto same = [&](int f) {
    const Image<float>& a = with.layers.at({"base", f});
    const Image<float>& b = without.layers.at({"base", f});
    return std::memcmp(a.row(0), b.row(0), a.bytes()) == 0;
  };
  EXPECT_TRUE(same(0));  // the first frame has no temporal guide
  EXPECT_FALSE(same(2));
}

// Spins until this process has used `seconds` more CPU time.
void burn_cpu(double seconds) {
  const auto cpu = [] {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
  };
  const double end = cpu() + seconds;
  volatile double sink = 0.0;
  while (cpu() < end)
    for (int i = 0; i < 1000; ++i) sink = sink + 1.0;
}

// RunOptions::stages: a frame's passes, its compositing and outputs, and the rest go to their
// stages (here passes and outputs that cost 20 and 10 ms of CPU each), and nothing changes.
TEST(Pipeline, StageClockChargesEachStageAndChangesNoFrame) {
  class SlowFrames : public SlidingFrames {
   public:
    using SlidingFrames::SlidingFrames;
    Image<float> passes(int frame) const override {
      burn_cpu(0.02);
      return SlidingFrames::passes(frame);
    }
  };
  class SlowStore : public MemoryStore {
   public:
    void write_frame(int f, ImageView<const float> c,
                     const std::vector<ImageView<const float>>& layers,
                     ImageView<const float> passes) override {
      burn_cpu(0.01);
      MemoryStore::write_frame(f, c, layers, passes);
    }
  };
  const Shot shot = tiny_shot();
  const SlowFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  MemoryStore plain;
  SlowStore timed;
  run_shot(shot, frames, ex, CompositeInputs{}, plain, RunOptions{});
  StageClock clock;
  clock.enter(StageClock::kPreviews);  // what run_shot charges nothing to
  RunOptions o;
  o.stages = &clock;
  const int calls = frames.calls;
  const double prepare = clock.seconds(StageClock::kPrepare).cpu;
  run_shot(shot, frames, ex, CompositeInputs{}, timed, o);
  EXPECT_EQ(clock.seconds(StageClock::kPrepare).cpu, prepare);
  EXPECT_EQ(clock.enter(StageClock::kPrepare), StageClock::kPreviews);  // handed back
  const int read = frames.calls - calls;
  EXPECT_GE(read, 4);
  EXPECT_GE(clock.seconds(StageClock::kPasses).cpu, 0.02 * read);
  EXPECT_GE(clock.seconds(StageClock::kComposite).cpu, 0.01 * 4);
  EXPECT_GT(clock.seconds(StageClock::kLayers).cpu, 0.0);
  for (int f = 0; f <= 3; ++f) EXPECT_TRUE(same_layer(plain, timed, f)) << f;
  EXPECT_EQ(plain.frames, timed.frames);
}

// RunOptions::concurrent_layers: a frame's layers made at once give the same values and fields,
// whether they start no chain there (every layer at the first frame, frame-by-frame layers at
// every frame) or continue one, sharing an advection field (same guide, patch size and seed) or
// each with its own.
TEST(Pipeline, ConcurrentLayersGiveTheSameFrames) {
  Shot shot = tiny_shot();
  ASSERT_TRUE(shot.layers[0].temporal.enabled);
  shot.layers.push_back(shot.layers[0]);
  shot.layers[1].name = "second";
  shot.layers[1].temporal.enabled = false;
  shot.layers.push_back(shot.layers[1]);
  shot.layers[2].name = "third";
  shot.layers[2].synth.seed = 7;
  shot.layers.push_back(shot.layers[0]);
  shot.layers[3].name = "shares_the_field";
  shot.layers[3].synth.uniformity = 2.0f * shot.layers[0].synth.uniformity + 1.0f;
  shot.layers.push_back(shot.layers[0]);
  shot.layers[4].name = "own_field";
  shot.layers[4].synth.seed = 11;
  const SlidingFrames frames(40, 30);
  const auto ex = tiny_exemplar();
  MemoryStore one, all;
  run_shot(shot, frames, ex, CompositeInputs{}, one, RunOptions{});
  RunOptions o;
  o.concurrent_layers = true;
  run_shot(shot, frames, ex, CompositeInputs{}, all, o);
  ASSERT_EQ(one.layers.size(), all.layers.size());
  for (const auto& [key, a] : one.layers) {
    const Image<float>& b = all.layers.at(key);
    EXPECT_EQ(std::memcmp(a.row(0), b.row(0), a.bytes()), 0) << key.first << " " << key.second;
  }
  ASSERT_EQ(one.fields.size(), all.fields.size());
  EXPECT_FALSE(one.fields.empty());
  for (const auto& [key, a] : one.fields) {
    const auto& b = all.fields.at(key);
    EXPECT_EQ(a.first, b.first) << key.first << " " << key.second;
    EXPECT_EQ(std::memcmp(a.second.row(0), b.second.row(0), a.second.bytes()), 0)
        << key.first << " " << key.second;
  }
}

TEST(Pipeline, ColourLayerTransfersRgbWithItsMask) {
  Shot shot = tiny_shot();
  shot.layers[0].single_colour = false;
  shot.layers[0].mask = {MaskKind::kLines, 3.0f, 0.5f};
  const SlidingFrames frames(40, 30);
  MemoryStore store;
  const RunReport r =
      run_shot(shot, frames, tiny_exemplar(), CompositeInputs{}, store, RunOptions{});
  EXPECT_EQ(r.synthesized, 4);
  const Image<float>& v = store.layers.at({"base", 2});
  ASSERT_EQ(v.channels(), 4);     // RGB + mask coverage
  EXPECT_EQ(v(21, 10, 3), 1.0f);  // the line sits at x = 20 + 2 in frame 2
  EXPECT_EQ(v(5, 10, 3), 0.0f);
  EXPECT_NE(v(21, 10, 0), v(21, 10, 2));  // colours, not one touch
}

TEST(Pipeline, UnknownLayerOptionIsAnError) {
  const Shot shot = tiny_shot();
  const SlidingFrames frames(40, 30);
  MemoryStore store;
  RunOptions o;
  o.layers = {"bsae"};
  try {
    run_shot(shot, frames, tiny_exemplar(), CompositeInputs{}, store, o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "layers");  // a neutral name: each front end re-spells it
  }
}

// RunOptions::cancel reaches the synthesis: asked after the first layer frame, the run stops
// inside the second with synth::Cancelled, the first written; never asked, nothing changes.
TEST(Pipeline, CancelStopsTheSynthesisInProgress) {
  const Shot shot = tiny_shot();
  const SlidingFrames frames(40, 30);
  MemoryStore store, plain, polled;
  RunOptions o;
  o.cancel = [&] { return store.layers.size() >= 1; };
  EXPECT_THROW(run_shot(shot, frames, tiny_exemplar(), CompositeInputs{}, store, o),
               synth::Cancelled);
  EXPECT_EQ(store.layers.size(), 1u);
  run_shot(shot, frames, tiny_exemplar(), CompositeInputs{}, plain, RunOptions{});
  RunOptions never;
  never.cancel = [] { return false; };
  run_shot(shot, frames, tiny_exemplar(), CompositeInputs{}, polled, never);
  for (int f = 0; f <= 3; ++f) EXPECT_TRUE(same_layer(plain, polled, f)) << f;
}

TEST(Pipeline, ContactSheetGrid) {
  std::vector<Image<float>> frames;
  for (int i = 0; i < 5; ++i) {
    frames.emplace_back(100, 50, 3);
    frames.back().fill(0.1f * i);
  }
  const Image<float> sheet = contact_sheet(frames, 4, 40);
  EXPECT_EQ(sheet.width(), 4 * 40 + 5 * 4);
  EXPECT_EQ(sheet.height(), 2 * 20 + 3 * 4);
  EXPECT_FLOAT_EQ(sheet(4 + 40 + 4 + 10, 4 + 10, 0), 0.1f);  // second thumbnail
  EXPECT_FLOAT_EQ(sheet(4 + 10, 4 + 20 + 4 + 10, 0), 0.4f);  // fifth, second row
}

}  // namespace
}  // namespace emaki::pipeline
