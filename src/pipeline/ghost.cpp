#include "pipeline/ghost.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/error.h"
#include "core/shot_keys.h"
#include "pipeline/qa_maps.h"
#include "pipeline/temporal_guide.h"
#include "render/passes.h"

namespace emaki::pipeline {

namespace {

// The mean of `w` over the patch_size window around each pixel (clamped at the edges).
Image<float> window_mean(const Image<float>& w, int patch_size) {
  const int width = w.width(), height = w.height(), r = patch_size / 2;
  Image<float> out(width, height, 1);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      double s = 0.0;
      int n = 0;
      for (int v = std::max(0, y - r); v <= std::min(height - 1, y + r); ++v)
        for (int u = std::max(0, x - r); u <= std::min(width - 1, x + r); ++u) s += w(u, v), ++n;
      out(x, y) = float(s / n);
    }
  return out;
}

}  // namespace

FrameGhost frame_ghost(const Layer& layer, ImageView<const float> current,
                       ImageView<const float> previous, ImageView<const float> reference,
                       ImageView<const float> passes, ImageView<const float> previous_passes,
                       int frame, Image<float>* map) {
  const int w = current.width, h = current.height;
  CHECK_EQ(reference.width, w);
  CHECK_EQ(passes.width, w);
  const int n = layer.single_colour ? 1 : 3;
  const int mask_channel = current.channels > n ? n : -1;
  const Image<float> mask = layer_mask(passes, layer.mask);
  // The evidence whether or not the run used it; the advection itself is the run's.
  Layer with_evidence = layer;
  with_evidence.temporal.confidence = true;
  const temporal::Advection adv =
      advect_layer(with_evidence, passes, mask, previous, previous_passes, frame);
  Image<float> weight;
  if (layer.temporal.confidence) {
    weight = window_mean(adv.confidence, layer.synth.patch_size);
  } else {
    weight.reset(w, h, 1);
    weight.fill(1.0f);
  }
  FrameGhost out;
  out.frame = frame;
  if (map) *map = empty_qa_map(w, h);
  GhostStats& s = out.stats;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* p = passes.at(x, y);
      if (p[render::kAlpha] < 1.0f || p[render::kOutline] > 0.0f || p[render::kObjectId] < 1.0f)
        continue;
      if (mask_channel >= 0 && current(x, y, mask_channel) < 1.0f) continue;
      const double diff = std::abs(double(current(x, y, 0)) - double(reference(x, y, 0)));
      if (adv.visible(x, y)) {
        ++s.visible, s.visible_diff_sum += diff;
        continue;
      }
      ++s.hidden;
      const double pull = double(adv.foreign(x, y)) * weight(x, y);
      s.foreign_sum += pull;
      if (map) {
        (*map)(x, y, 0) = float(std::clamp(pull, 0.0, 1.0));
        (*map)(x, y, 1) = 1.0f;
      }
      s.diff_sum += diff;
    }
  return out;
}

GhostStats measure_ghost(const Layer& layer, const FrameSource& frames, const Store& store,
                         int first, int last, const std::function<Image<float>(int)>& reference,
                         const std::function<void(const FrameGhost&)>& each,
                         const std::function<void(int, const Image<float>&)>& maps) {
  CHECK_LT(first, last);
  if (!layer.temporal.enabled)
    throw Error(shot_keys::layer(layer.name),
                "is not temporal (temporal = false): it has no ghosts");
  for (int f = first; f <= last; ++f)
    if (!store.has_layer(layer, f))
      throw Error(shot_keys::layer(layer.name), fmt::format("frame {} is not synthesized yet", f));
  GhostStats total;
  Image<float> prev = store.read_layer(layer, first), prev_passes = frames.passes(first);
  for (int f = first + 1; f <= last; ++f) {
    Image<float> cur = store.read_layer(layer, f), cur_passes = frames.passes(f);
    const Image<float> ref = reference(f);
    Image<float> map;
    const FrameGhost fg =
        frame_ghost(layer, cur.cview(), prev.cview(), ref.cview(), cur_passes.cview(),
                    prev_passes.cview(), f, maps ? &map : nullptr);
    if (each) each(fg);
    if (maps) maps(f, map);
    total.add(fg.stats);
    prev = std::move(cur);
    prev_passes = std::move(cur_passes);
  }
  return total;
}

}  // namespace emaki::pipeline
