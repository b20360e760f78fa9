// Ghosts of the temporal chain (emaki qa ghost): where a surface appears that was hidden at t-1
// (ground uncovered by a swinging tail, a limb passing in front), the advected previous frame
// has nothing right to carry and holds the touch of what covered it. For those pixels, this
// measures how much of the temporal guide's pull came from another object, and how far the
// temporal result lies from a frame-by-frame one.
#pragma once

#include <functional>

#include "core/image.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "pipeline/shot_description.h"

namespace emaki::pipeline {

struct GhostStats {
  long hidden = 0;           // pixels whose surface was hidden at t-1
  double foreign_sum = 0.0;  // their foreign share x the temporal guide's weight there
  double diff_sum = 0.0;     // their |temporal - frame by frame|
  long visible = 0;          // the other pixels counted (same rules), for comparison
  double visible_diff_sum = 0.0;
  // The share of the temporal guide's pull over hidden pixels that came from another object.
  double ghost_share() const { return hidden ? foreign_sum / double(hidden) : 0.0; }
  double diff() const { return hidden ? diff_sum / double(hidden) : 0.0; }
  double visible_diff() const { return visible ? visible_diff_sum / double(visible) : 0.0; }
  void add(const GhostStats& o) {
    hidden += o.hidden, foreign_sum += o.foreign_sum, diff_sum += o.diff_sum;
    visible += o.visible, visible_diff_sum += o.visible_diff_sum;
  }
};

struct FrameGhost {
  int frame = 0;
  GhostStats stats;
};

// One frame t of `layer`: `current` its temporal result at t, `previous` at t-1 (the run's
// B'(t-1)), `reference` a frame-by-frame result at t (value channels, then mask coverage when
// masked). The advection is recomputed as the run did it (same seed), with its evidence.
// Counted pixels are fully covered, carry an object id, are on no line and, for a masked
// layer, lie inside its mask; hidden ones are those whose surface point was not visible at t-1
// (temporal::visible_before: motion, object id and rest position). A pixel's weight is the
// mean of the temporal guide's weight map (the confidence; 1 without it) over the patch around
// it: the share of the patches voting it that carry the guide. With `map`, it is made the
// frame's ghost map (pipeline/qa_maps.h): each hidden pixel's foreign share times that weight.
FrameGhost frame_ghost(const Layer& layer, ImageView<const float> current,
                       ImageView<const float> previous, ImageView<const float> reference,
                       ImageView<const float> passes, ImageView<const float> previous_passes,
                       int frame, Image<float>* map = nullptr);

// Frames first + 1 .. last of `layer` in `store` (first < last), against `reference(f)`, the
// frame-by-frame result of frame f; `each` (may be empty) sees each frame's figures, `maps` (may
// be empty) each frame's ghost map. Throws emaki::Error naming the layer when a frame is not
// synthesized yet or the layer is not temporal.
GhostStats measure_ghost(const Layer& layer, const FrameSource& frames, const Store& store,
                         int first, int last, const std::function<Image<float>(int)>& reference,
                         const std::function<void(const FrameGhost&)>& each,
                         const std::function<void(int, const Image<float>&)>& maps = {});

}  // namespace emaki::pipeline
