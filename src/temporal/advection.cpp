#include "temporal/advection.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace emaki::temporal {

Advection advect(const AdvectionInputs& in, const synth::Params& params) {
  const ImageView<const float> prev = in.previous_stylized;
  CHECK(!prev.empty());
  const int n = in.value_channels;
  CHECK(n == 1 || n == 3);
  CHECK_GE(prev.channels, n);
  const bool masked = prev.channels > n;
  // The style is B'(t-1)'s value, with the empty value where it had no content, so that the
  // advection never copies the transparent area's zeros into the current frame.
  Image<float> style(prev.width, prev.height, n);
  for (int y = 0; y < prev.height; ++y)
    for (int x = 0; x < prev.width; ++x) {
      const float* p = prev.at(x, y);
      const float a = masked ? p[n] : 1.0f;
      for (int c = 0; c < n; ++c) style(x, y, c) = a * p[c] + (1.0f - a) * in.empty_value;
    }
  synth::Inputs inputs;
  inputs.style = style.cview();
  inputs.style_name = "previous frame";
  inputs.guides.push_back({in.guide_name, in.previous_guide, in.current_guide, 1.0f});
  if (in.current_mask) inputs.target_mask = *in.current_mask;
  synth::Params p = params;
  p.uniformity = 0.0f;
  // Consecutive frames are nearly aligned: the field starts at the identity and is refined at
  // full resolution only, within a radius that covers a frame's motion.
  p.init = synth::FieldInit::kIdentity;
  p.pyramid_levels = 1;
  p.search_vote_iters = 1;
  p.patch_match_iters = 2;
  // Matched on the position guide alone: B'(t-1) is only carried along. A style term would
  // compare it with the current estimate of B'adv, which starts as the unmoved B'(t-1), and
  // hold patches back where the frame moved (measured: more flicker, docs/temporal.md).
  p.style_weight = 0.0f;
  p.search_radius = in.search_radius > 0
                        ? in.search_radius
                        : std::max(8, int(std::lround(std::max(prev.width, prev.height) / 60.0)));
  synth::OutputRequest request;
  request.nnf = request.error = in.surfaces.has_value();
  synth::Result r = synth::synthesize(inputs, p, request);
  Advection out;
  if (in.surfaces) {
    out.visible = visible_before(*in.surfaces);
    out.foreign = foreign_share(r.nnf, *in.surfaces, p.patch_size, p.patch_size / 2);
    out.confidence = confidence(out.visible, out.foreign, r.error, p.patch_size, in.confidence);
  }
  if (r.image.channels() == n) {
    out.value = std::move(r.image);
    return out;
  }
  // Drop the alpha the mask added; outside the mask the value is the empty value.
  out.value.reset(r.image.width(), r.image.height(), n);
  for (int y = 0; y < out.value.height(); ++y)
    for (int x = 0; x < out.value.width(); ++x) {
      const float a = r.image(x, y, n);
      for (int c = 0; c < n; ++c)
        out.value(x, y, c) = a * r.image(x, y, c) + (1.0f - a) * in.empty_value;
    }
  return out;
}

}  // namespace emaki::temporal
