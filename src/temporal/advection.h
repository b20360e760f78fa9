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
#include "temporal/confidence.h"

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
  // How far, in pixels, a point may move between the two frames and still be found by the
  // random search (propagation carries matches further); 0: the larger frame side / 60 (16 at
  // 960x540, 32 at 1920x1080), at least 8.
  int search_radius = 0;
  // With the surfaces of both frames, the advection also says where B'adv can be trusted.
  std::optional<Surfaces> surfaces;
  ConfidenceParams confidence;
  // With surfaces, optionally: the layer's own guides (stacked channels in [0, 1]) of frames
  // t-1 and t; the confidence then also drops where they changed along the field
  // (ConfidenceParams::change_*): a lighting change is re-synthesized, not carried.
  std::optional<ImageView<const float>> previous_layer_guides, current_layer_guides;
  // False: the confidence alone (with surfaces), for a layer whose temporal guide has weight 0;
  // B'adv is then not voted and Advection::value stays empty.
  bool value = true;
};

struct Advection {
  Image<float> value;  // B'adv, the size of the current frame, `value_channels` channels (or
                       // empty: AdvectionInputs::value)
  // With surfaces (else empty): the confidence in [0, 1] and the evidence it was made from.
  Image<float> confidence;
  Image<uint8_t> visible;  // visible_before()
  Image<float> foreign;    // foreign_share() of the advection's field
};

// The advection's field of one frame: for each pixel of frame t, the centre of the patch of
// t-1 it matches on the position guide alone (style weight 0), over the whole frame, with its
// patch error; with surfaces, visible_before() too. It does not depend on B'(t-1) or on a
// layer's mask, so one field serves every layer of a frame that advects with the same guide,
// patch size and seed (pipeline/temporal_guide.h). Reads `in`'s guides, search radius and
// surfaces only. With surfaces it also keeps the part of the confidence's evidence that no
// layer changes: visible_before() and the id shares of t-1 that foreign_share() reads.
struct AdvectionField {
  Image<int32_t> nnf;      // the current frame's size, 2 channels
  Image<float> error;      // EbSynth units
  Image<uint8_t> visible;  // with surfaces (else empty)
  IdShares shares;         // with surfaces: id_shares(previous surfaces, patch_size / 2)
  int patch_size = 0;
};
AdvectionField advection_field(const AdvectionInputs& in, const synth::Params& params);

// B'adv (and, with surfaces, its confidence): B'(t-1) carried along `field` (computed here when
// null). `params` are the layer's
// synthesis settings (patch size, seed — which should differ from the main transfer's); the
// uniformity term is turned off, because an advection is a warp: spreading the use of
// B'(t-1)'s patches evenly would pull them off the motion; for the same reason patches are
// matched on the position guide alone (style weight 0). The schedule is the advection's own:
// the field starts at the identity (the two frames are nearly aligned) and one search-vote
// iteration of two PatchMatch sweeps at full resolution, random search within
// `search_radius`, refines it; with surfaces it starts where their motion vectors point instead,
// and one sweep refines it. Measured on the example against the main transfer's multiscale
// schedule with a style weight of 1 against the guide's 1000: less flicker and a third of the
// advection's time (docs/design/advection.md). The field covers the whole frame; with a mask, B'adv
// is voted inside it (dilated by the patch radius, as the synthesizer does) from the patches
// centred there.
Advection advect(const AdvectionInputs& in, const synth::Params& params,
                 const AdvectionField* field = nullptr);

}  // namespace emaki::temporal
