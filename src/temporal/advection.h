// Temporal noise reduction as Todo et al. (SIGGRAPH Asia 2024) define it: for frame t after the
// first, the previous stylized frame B'(t-1) is carried to frame t by a guided transfer whose
// source guide is a position pass of t-1 and whose target guide is the same pass of t. The
// result, B'adv, then joins frame t's main transfer as one more guide pair: the exemplar A' on
// the source side, B'adv on the target side.
#pragma once

#include <optional>
#include <string>

#include "core/image.h"
#include "synth/synthesizer.h"

namespace emaki::temporal {

// What the advection reads. The guide is a position pass — the paper's normalised world
// position, or (beyond the paper) rest-pose position plus object id, which follows a surface
// that moves or deforms — of frame t-1 (source) and of frame t (target).
struct AdvectionInputs {
  ImageView<const float> previous_stylized;  // B'(t-1): `value_channels` values, then optional mask
  int value_channels = 1;                    // 1 (single colour) or 3
  ImageView<const float> previous_guide;     // frame t-1
  ImageView<const float> current_guide;      // frame t
  std::string guide_name = "position";
  std::optional<ImageView<const float>> current_mask;  // where frame t is synthesized (1 ch)
  float empty_value = 1.0f;  // stands for B'(t-1) where it was not synthesized (outside its mask)
  // Weight of the position guide against the style's 1. Position passes are smooth: at shot
  // resolution neighbouring pixels differ by a fraction of a quantisation level, so a weight
  // near the style's lets texture similarity outvote the motion (measured: a 4-pixel shift on
  // a 64-pixel frame came out as 2 pixels at weight 1, exact at 10 and above).
  float guide_weight = 1000.0f;
};

// B'adv, the size of the current frame, `value_channels` channels. `params` are the layer's
// synthesis settings (the seed should differ from the main transfer's); the uniformity term is
// turned off, because an advection is a warp: spreading the use of B'(t-1)'s patches evenly
// would pull them off the motion.
Image<float> advect(const AdvectionInputs& in, const synth::Params& params);

}  // namespace emaki::temporal
