// Where the advected previous frame can guide the current one. B'adv is B'(t-1) carried along
// the advection's field; at a pixel whose surface point was hidden at t-1 (ground uncovered by
// a swinging tail, a limb passing in front) there is nothing right to carry, and B'adv holds a
// stretched copy of what lay next to the cover, bled into by the cover's own patches: kept by
// the main transfer, it becomes a streak that trails the cover
// (docs/design/temporal-confidence.md). The confidence is 1 where the advection's own evidence says
// the surface was visible and carried from itself, 0 where it was not, and the main transfer uses
// it as the temporal guide's weight map.
#pragma once

#include <vector>

#include "core/image.h"

namespace emaki::temporal {

// The surface each pixel shows: rest-pose position (3 channels, any fixed space) and object id
// (1 channel, integers; 0: nothing) — of frames t-1 and t — and the motion from t to t-1.
struct Surfaces {
  ImageView<const float> previous;  // frame t-1, 4 channels
  ImageView<const float> current;   // frame t, 4 channels
  ImageView<const float> motion;  // frame t, 2 channels: pixels from here to the same point at t-1
};

// 1 where the surface point a pixel of frame t shows was visible at t-1: one of the pixels
// (one to four) that a bilinear sample at the end of its motion vector reads in t-1 shows the
// same object with a rest position within `tolerance` pixel footprints of it (a footprint: the
// largest rest-position step to a neighbour of the same object at t). 0 where it was hidden or
// outside the frame. This is `emaki qa flicker`'s occlusion test (the same object around the
// motion's end) with the rest position added, so that a limb passing in front of its own body
// counts as a cover too.
Image<uint8_t> visible_before(const Surfaces& s, float tolerance = 3.0f);

// For each pixel of frame t, the share of its B'adv value that came from another object than
// the one it shows. B'adv at a pixel is the vote of the patches over it, each matched to a patch
// of t-1 by `nnf` (patch centres in t-1, -1 outside its mask: not counted), so it reads one
// pixel of t-1 per patch; and B'(t-1) at that pixel was itself the vote of the patches of t-1's
// synthesis within `footprint` pixels of it (the patch radius), each centred on some object.
// A vote counts the share of those centres on another object: a value carried from next to
// another object's silhouette carries that object's bleed. Pixels no patch votes are 0.
Image<float> foreign_share(const Image<int32_t>& nnf, const Surfaces& s, int patch_size,
                           int footprint);

// For each object id of frame t-1 (Surfaces::previous' channel 3), the share of the pixels within
// `radius` of each pixel (clamped window) that show it: foreign_share()'s evidence from frame t-1,
// which depends on neither a layer's field nor its mask, so one serves every layer of a frame.
struct IdShares {
  int radius = -1;
  std::vector<float> ids;
  std::vector<Image<float>> share;  // parallel to ids
  bool empty() const { return radius < 0; }
  // The shares of id k, or null for an id not present (its share is 0 everywhere).
  const Image<float>* find(float k) const {
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] == k) return &share[i];
    return nullptr;
  }
};
IdShares id_shares(ImageView<const float> previous, int radius);

// foreign_share(nnf', s, patch_size, shares.radius) where nnf' is `nnf` with -1 at the patch
// centres outside `active` (empty: none), from `shares` (id_shares(s.previous, footprint)).
Image<float> foreign_share(const Image<int32_t>& nnf, const Image<uint8_t>& active,
                           const Surfaces& s, int patch_size, const IdShares& shares);

// How the evidence becomes a confidence (defaults measured on the example,
// docs/design/temporal-confidence.md).
struct ConfidenceParams {
  // The advection's patch error as an RMS guide difference per channel (guide values in [0, 1]):
  // full confidence up to error_full, none from error_none, linear between.
  float error_full = 0.02f;
  float error_none = 0.08f;
  // The foreign share: no confidence from foreign_none on, linear below it (1: 1 - foreign).
  float foreign_none = 1.0f;
  // The change of the layer's own guides along the advection (temporal/guide_change.h): full
  // confidence up to change_full, none from change_none, linear between; change_none <= 0: not
  // counted.
  float change_full = 0.0f;
  float change_none = 0.0f;
  // Shrink the confident region by this many pixels, so that patches centred next to an
  // untrusted pixel do not carry it either (the weight map applies at patch centres); 0: none.
  // 2, the radius of the default 5 x 5 patch: no patch over an uncovered pixel carries the
  // guide (docs/design/temporal-confidence.md).
  int erode = 2;
};

// visible x the foreign ramp x the error ramp (x the change ramp, with `change`), eroded. `error`:
// the advection's per-pixel patch error in EbSynth units (synth::Result::error) over guides whose
// weights sum to 1, which makes sqrt(error / (65025 x patch_size^2)) the RMS guide difference;
// `patch_size` the advection's.
Image<float> confidence(const Image<uint8_t>& visible, const Image<float>& foreign,
                        const Image<float>& error, int patch_size, const ConfidenceParams& params,
                        const Image<float>& change = {});

}  // namespace emaki::temporal
