#include "temporal/advection.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/parallel.h"
#include "synth/voting.h"
#include "temporal/guide_change.h"

namespace emaki::temporal {

namespace {

// The advection's own schedule on top of the layer's settings (see advect()).
synth::Params field_params(const synth::Params& params, int search_radius, int width, int height) {
  synth::Params p = params;
  p.uniformity = 0.0f;
  // Consecutive frames are nearly aligned: the field starts at the identity (or, with motion
  // vectors, where they point: advection_field() then runs one sweep) and is refined at full
  // resolution only, within a radius that covers a frame's motion.
  p.init = synth::FieldInit::kIdentity;
  p.pyramid_levels = 1;
  p.search_vote_iters = 1;
  p.patch_match_iters = 2;
  // Matched on the position guide alone: B'(t-1) is only carried along. A style term would
  // compare it with the current estimate of B'adv, which starts as the unmoved B'(t-1), and
  // hold patches back where the frame moved (measured: more flicker, docs/design/advection.md).
  p.style_weight = 0.0f;
  p.search_radius = search_radius > 0
                        ? search_radius
                        : std::max(8, int(std::lround(std::max(width, height) / 60.0)));
  return p;
}

// Where a masked synthesis works: the mask (> 0) dilated by the patch radius — the
// synthesizer's own rule (synth::Inputs::target_mask).
Image<uint8_t> active_region(ImageView<const float> mask, int r) {
  Image<uint8_t> inside(mask.width, mask.height, 1);
  parallel_rows(mask.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < mask.width; ++x) inside(x, y) = mask.at(x, y)[0] > 0.0f ? 1 : 0;
  });
  return synth::dilate_mask(inside, r);
}

// The field's start: each pixel at the end of its motion vector (the pixel of t-1 it shows),
// rounded and kept where a patch fits; the pixel itself where the vector is not finite.
Image<int32_t> motion_start(ImageView<const float> motion, int patch_size) {
  const int w = motion.width, h = motion.height, r = patch_size / 2;
  Image<int32_t> start(w, h, 2);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const float* m = motion.at(x, y);
        const bool finite = std::isfinite(m[0]) && std::isfinite(m[1]);
        const float sx = finite ? x + m[0] : float(x), sy = finite ? y + m[1] : float(y);
        start(x, y, 0) = int(std::lround(std::clamp(sx, float(r), float(w - 1 - r))));
        start(x, y, 1) = int(std::lround(std::clamp(sy, float(r), float(h - 1 - r))));
      }
  });
  return start;
}

}  // namespace

AdvectionField advection_field(const AdvectionInputs& in, const synth::Params& params) {
  const int w = in.previous_guide.width, h = in.previous_guide.height;
  // The style takes no part in the match (weight 0): a blank one stands for B'(t-1).
  Image<float> blank(w, h, 1);
  synth::Inputs inputs;
  inputs.style = blank.cview();
  inputs.style_name = "previous frame";
  inputs.guides.push_back({in.guide_name, in.previous_guide, in.current_guide, 1.0f});
  synth::Params p = field_params(params, in.search_radius, w, h);
  // With the renderer's motion vectors the field starts where they point, and one sweep refines
  // it: on the Fox at 960x540 and the sunset's moving light the same flicker and texture as two
  // sweeps from the identity, for half the field's time (docs/design/advection.md).
  Image<int32_t> start;
  const ImageView<const float> motion =
      in.surfaces ? in.surfaces->motion : ImageView<const float>{};
  if (motion.width == w && motion.height == h && motion.channels >= 2 && w >= p.patch_size &&
      h >= p.patch_size) {
    start = motion_start(motion, p.patch_size);
    p.initial_nnf = start.cview();
    p.patch_match_iters = 1;
  }
  synth::OutputRequest request;
  request.nnf = request.error = true;
  synth::Result r = synth::synthesize(inputs, p, request);
  AdvectionField f;
  f.nnf = std::move(r.nnf);
  f.error = std::move(r.error);
  f.patch_size = p.patch_size;
  if (in.surfaces) {
    f.visible = visible_before(*in.surfaces);
    f.shares = id_shares(in.surfaces->previous, f.patch_size / 2);
  }
  return f;
}

namespace {

// The confidence of a layer's B'adv and its evidence: the patches that vote it (those centred
// inside its active region, `active`; empty: all) and their errors.
void add_confidence(const AdvectionInputs& in, const AdvectionField& field,
                    const Image<uint8_t>& active, Advection& out) {
  const int w = field.nnf.width(), h = field.nnf.height(), patch = field.patch_size;
  Image<float> error = field.error.clone();
  if (!active.empty())
    parallel_rows(h, 32, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x)
          if (!active(x, y)) error(x, y) = 0.0f;
    });
  out.visible = field.visible.empty() ? visible_before(*in.surfaces) : field.visible.clone();
  // A field made without surfaces has no shared evidence: it is counted here.
  const bool shared = !field.shares.empty();
  const IdShares own_shares = shared ? IdShares{} : id_shares(in.surfaces->previous, patch / 2);
  out.foreign =
      foreign_share(field.nnf, active, *in.surfaces, patch, shared ? field.shares : own_shares);
  Image<float> change;
  if (in.previous_layer_guides && in.current_layer_guides && in.confidence.change_none > 0.0f)
    change = guide_change(field.nnf, *in.previous_layer_guides, *in.current_layer_guides);
  out.confidence = confidence(out.visible, out.foreign, error, patch, in.confidence, change);
}

}  // namespace

Advection advect(const AdvectionInputs& in, const synth::Params& params,
                 const AdvectionField* field) {
  const ImageView<const float> prev = in.previous_stylized;
  CHECK(!prev.empty());
  const int n = in.value_channels;
  CHECK(n == 1 || n == 3);
  CHECK_GE(prev.channels, n);
  AdvectionField own;
  if (field == nullptr) {
    own = advection_field(in, params);
    field = &own;
  }
  const int w = field->nnf.width(), h = field->nnf.height(), patch = field->patch_size;
  Image<uint8_t> active;
  if (in.current_mask) active = active_region(*in.current_mask, patch / 2);
  Advection out;
  if (in.surfaces) add_confidence(in, *field, active, out);
  if (!in.value) return out;
  // The style is B'(t-1)'s value, with the empty value where it had no content, so that the
  // advection never copies the transparent area's zeros into the current frame.
  const bool masked = prev.channels > n;
  Image<float> style(prev.width, prev.height, n);
  parallel_rows(prev.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < prev.width; ++x) {
        const float* p = prev.at(x, y);
        const float a = masked ? p[n] : 1.0f;
        for (int c = 0; c < n; ++c) style(x, y, c) = a * p[c] + (1.0f - a) * in.empty_value;
      }
  });
  Image<float> voted;
  synth::vote(synth::Plane(style.cview()), field->nnf, field->error, active, patch,
              params.vote_mode, voted);
  if (!in.current_mask) {
    out.value = std::move(voted);
    return out;
  }
  // Outside the mask the value is the empty value.
  out.value.reset(w, h, n);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const float a = std::clamp(in.current_mask->at(x, y)[0], 0.0f, 1.0f);
        for (int c = 0; c < n; ++c)
          out.value(x, y, c) =
              a * (a <= 0.0f ? 0.0f : voted(x, y, c)) + (1.0f - a) * in.empty_value;
      }
  });
  return out;
}

}  // namespace emaki::temporal
