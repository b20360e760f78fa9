// Temporal error of a stylized sequence (emaki qa flicker): for each frame t after the first,
// the mean absolute difference between B'(t) and B'(t-1) sampled where the renderer's motion
// vectors say the same surface point was, over pixels visible in both frames.
#pragma once

#include <functional>
#include <map>

#include "core/image.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "pipeline/shot_description.h"

namespace emaki::pipeline {

struct FlickerStats {
  double sum = 0.0;
  long pixels = 0;
  double mean() const { return pixels ? sum / double(pixels) : 0.0; }
};

struct FrameFlicker {
  int frame = 0;
  FlickerStats all, objects, ground;  // objects: id >= 2; ground: id 1
  std::map<int, FlickerStats> by_id;  // per value of the object_id pass (1: the ground)
};

// A sequence's flicker: the frame means averaged with equal weight per frame (`pixels` counts
// the frames). Per object id, over the frames in which the id has pixels measured.
struct SequenceFlicker {
  FlickerStats all, objects, ground;
  std::map<int, FlickerStats> by_id;
  void add(const FrameFlicker& f) {
    all.sum += f.all.mean(), all.pixels += 1;
    objects.sum += f.objects.mean(), objects.pixels += 1;
    ground.sum += f.ground.mean(), ground.pixels += 1;
    for (const auto& [id, s] : f.by_id)
      if (s.pixels > 0) by_id[id].sum += s.mean(), by_id[id].pixels += 1;
  }
};

// `current`/`previous`: layer values (channel 0 is used; a masked layer's coverage is its
// channel `mask_channel`, -1 for none); passes in the layout of render/passes.h. A pixel counts
// when it and the four pixels it samples in t-1 are fully covered, carry the same object id, no
// line (silhouettes are where points hide) and, for a masked layer, lie inside both masks.
// With `map`, it is made the frame's flicker map (pipeline/qa_maps.h): each counted pixel's
// difference. With `select` (1 channel, the frame's size), only the pixels where it is non-zero
// count.
FrameFlicker frame_flicker(ImageView<const float> current, ImageView<const float> previous,
                           ImageView<const float> current_passes,
                           ImageView<const float> previous_passes, int mask_channel,
                           Image<float>* map = nullptr, const Image<uint8_t>* select = nullptr);

// The flicker of `layer`'s finished frames [first, last] (first < last) in `store`, with the
// passes of `frames`; `each` (may be empty) sees each frame's figures in frame order, and `maps`
// (may be empty) each frame's flicker map. Throws emaki::Error naming the layer ("layers.NAME")
// when a frame is not synthesized yet.
SequenceFlicker measure_flicker(const Layer& layer, const FrameSource& frames, const Store& store,
                                int first, int last,
                                const std::function<void(const FrameFlicker&)>& each,
                                const std::function<void(int, const Image<float>&)>& maps = {});

}  // namespace emaki::pipeline
