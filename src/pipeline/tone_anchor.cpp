#include "pipeline/tone_anchor.h"

#include <algorithm>
#include <cmath>
#include <variant>
#include <vector>

#include "core/check.h"
#include "core/parallel.h"
#include "pipeline/frames.h"
#include "synth/pyramid.h"
#include "temporal/guide_change.h"

namespace emaki::pipeline {

namespace {

// A plane as floats, normalised as the synthesizer reads it (core/image.h).
Image<float> to_float(const synth::Plane& plane) {
  return std::visit(
      [](const auto& v) {
        Image<float> out(v.width, v.height, v.channels);
        parallel_rows(v.height, 32, [&](int y0, int y1) {
          for (int y = y0; y < y1; ++y)
            for (int x = 0; x < v.width; ++x)
              for (int c = 0; c < v.channels; ++c) out(x, y, c) = normalised(v(x, y, c));
        });
        return out;
      },
      plane);
}

Image<float> halve(Image<float> im, int halvings) {
  for (int i = 0; i < halvings; ++i) im = synth::downsample(im.cview());
  return im;
}

// halve(to_float(plane)), a float plane halved from where it lies, not from a copy.
Image<float> halve(const synth::Plane& plane, int halvings) {
  const auto* f = std::get_if<ImageView<const float>>(&plane);
  if (f == nullptr || halvings <= 0) return halve(to_float(plane), halvings);
  return halve(synth::downsample(*f), halvings - 1);
}

// Bilinear, pixel centres aligned.
float sample(const Image<float>& im, float x, float y, int c) {
  x = std::clamp(x, 0.0f, float(im.width() - 1));
  y = std::clamp(y, 0.0f, float(im.height() - 1));
  const int x0 = int(x), y0 = int(y);
  const int x1 = std::min(x0 + 1, im.width() - 1), y1 = std::min(y0 + 1, im.height() - 1);
  const float fx = x - float(x0), fy = y - float(y0);
  return (im(x0, y0, c) * (1 - fx) + im(x1, y0, c) * fx) * (1 - fy) +
         (im(x0, y1, c) * (1 - fx) + im(x1, y1, c) * fx) * fy;
}

// The small transfer's field at full size: each small pixel's patch spread over the block of
// 2^halvings pixels it covers, offset within it; (-1, -1) stays outside.
Image<int32_t> spread_field(const Image<int32_t>& small, int width, int height, int halvings) {
  Image<int32_t> out(width, height, 2);
  parallel_rows(height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x) {
        const int xs = std::min(x >> halvings, small.width() - 1);
        const int ys = std::min(y >> halvings, small.height() - 1);
        const int32_t sx = small(xs, ys, 0), sy = small(xs, ys, 1);
        const bool in = sx >= 0 && sy >= 0;
        out(x, y, 0) = in ? (sx << halvings) + (x - (xs << halvings)) : -1;
        out(x, y, 1) = in ? (sy << halvings) + (y - (ys << halvings)) : -1;
      }
  });
  return out;
}

}  // namespace

AnchorExemplar anchor_exemplar(const synth::Plane& style, const std::vector<synth::Plane>& sources,
                               int halvings) {
  CHECK_GE(halvings, 1);
  AnchorExemplar e;
  e.halvings = halvings;
  e.planes.push_back(halve(style, halvings));
  for (const synth::Plane& p : sources) e.planes.push_back(halve(p, halvings));
  return e;
}

Anchor anchor_tone(const synth::Inputs& inputs, const AnchorExemplar& exemplar,
                   const synth::Params& params, ImageView<const float> advected, int value_channels,
                   const Image<float>& mask, float sigma, float rate) {
  const int halvings = exemplar.halvings;
  CHECK_EQ(exemplar.planes.size(), inputs.guides.size() + 1);
  // The small inputs, kept alive while the small transfer reads them.
  std::vector<Image<float>> keep;
  keep.reserve(2 * inputs.guides.size());
  auto small = [&](const synth::Plane& p) -> synth::Plane {
    keep.push_back(halve(p, halvings));
    return synth::Plane(keep.back().cview());
  };
  synth::Inputs s;
  s.style = exemplar.planes[0].cview();
  s.style_name = inputs.style_name;
  for (std::size_t i = 0; i < inputs.guides.size(); ++i) {
    const synth::GuidePair& g = inputs.guides[i];
    synth::GuidePair h = g;
    h.source = exemplar.planes[i + 1].cview();
    h.target = small(g.target);
    if (g.weight_map) h.weight_map = small(*g.weight_map);
    s.guides.push_back(h);
  }
  // Too small to synthesize at that size: no anchor.
  const int least = 2 * params.patch_size + 1;
  const synth::Plane& t0 = s.guides.front().target;
  if (std::min(synth::plane_width(t0), synth::plane_height(t0)) < least ||
      std::min(synth::plane_width(s.style), synth::plane_height(s.style)) < least)
    return {};
  Image<float> small_mask;
  if (!mask.empty()) {
    small_mask = halve(extract(mask.cview(), 0, mask.channels()), halvings);
    bool any = false;
    for (int y = 0; y < small_mask.height() && !any; ++y)
      for (int x = 0; x < small_mask.width() && !any; ++x) any = small_mask(x, y) > 0.5f;
    if (!any) return {};
    s.target_mask = small_mask.cview();
  }
  synth::Params p = params;
  p.initial_nnf = {};
  p.progress = nullptr;
  synth::OutputRequest request;
  request.nnf = true;
  const synth::Result fresh = synth::synthesize(s, p, request);

  Anchor a;
  const synth::Plane& full = inputs.guides.front().target;
  a.nnf = spread_field(fresh.nnf, synth::plane_width(full), synth::plane_height(full), halvings);
  a.fresh = extract(fresh.image.cview(), 0, value_channels);
  a.halvings = halvings;
  if (advected.empty()) {
    a.small_mask = std::move(small_mask);
    return a;
  }
  // The difference, fresh minus carried, at the small size, low-passed inside the mask.
  const int n = value_channels;
  const Image<float> carried = halve(extract(advected, 0, n), halvings);
  const int sw = carried.width(), sh = carried.height();
  CHECK_EQ(fresh.image.width(), sw);
  Image<float> diff(sw, sh, n);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x)
      for (int c = 0; c < n; ++c) diff(x, y, c) = fresh.image(x, y, c) - carried(x, y, c);
  const Image<float> smooth = temporal::low_pass(
      diff.cview(), sigma, small_mask.empty() ? ImageView<const float>{} : small_mask.cview());

  a.small_mask = std::move(small_mask);
  Image<float>& out = a.target;
  out.reset(advected.width, advected.height, n);
  const float fx = float(sw) / float(advected.width), fy = float(sh) / float(advected.height);
  parallel_rows(advected.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < advected.width; ++x)
        for (int c = 0; c < n; ++c) {
          const float d = rate * sample(smooth, (float(x) + 0.5f) * fx - 0.5f,
                                        (float(y) + 0.5f) * fy - 0.5f, c);
          out(x, y, c) = std::clamp(advected(x, y, c) + d, 0.0f, 1.0f);
        }
  });
  return a;
}

void match_ink(Image<float>& layer, int value_channels, const Anchor& a, const Image<float>& mask,
               const Image<float>& confidence, float sigma, float share) {
  if (a.fresh.empty() || share <= 0.0f) return;
  const int n = value_channels;
  // Ink below this floor counts as bare paper on both sides: the scale stays near 1 there.
  constexpr float kFloor = 0.02f;
  const Image<float> small = halve(extract(layer.cview(), 0, n), a.halvings);
  const int sw = small.width(), sh = small.height();
  CHECK_EQ(a.fresh.width(), sw);
  CHECK_EQ(a.fresh.height(), sh);
  Image<float> ink_fresh(sw, sh, n), ink_chain(sw, sh, n);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x)
      for (int c = 0; c < n; ++c) {
        ink_fresh(x, y, c) = 1.0f - a.fresh(x, y, c);
        ink_chain(x, y, c) = 1.0f - small(x, y, c);
      }
  const ImageView<const float> m =
      a.small_mask.empty() ? ImageView<const float>{} : a.small_mask.cview();
  const Image<float> lf = temporal::low_pass(ink_fresh.cview(), sigma, m);
  const Image<float> lc = temporal::low_pass(ink_chain.cview(), sigma, m);
  Image<float> scale(sw, sh, n);
  for (int y = 0; y < sh; ++y)
    for (int x = 0; x < sw; ++x)
      for (int c = 0; c < n; ++c) {
        const float r = std::clamp((lf(x, y, c) + kFloor) / (lc(x, y, c) + kFloor), 0.5f, 2.0f);
        scale(x, y, c) = 1.0f + share * (r - 1.0f);
      }
  const int w = layer.width(), h = layer.height();
  const float fx = float(sw) / float(w), fy = float(sh) / float(h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (!mask.empty() && mask(x, y) <= 0.5f) continue;
      const float trust = confidence.empty() ? 1.0f : std::clamp(confidence(x, y), 0.0f, 1.0f);
      for (int c = 0; c < n; ++c) {
        const float k = 1.0f + trust * (sample(scale, (float(x) + 0.5f) * fx - 0.5f,
                                               (float(y) + 0.5f) * fy - 0.5f, c) -
                                        1.0f);
        layer(x, y, c) = std::clamp(1.0f - k * (1.0f - layer(x, y, c)), 0.0f, 1.0f);
      }
    }
}

}  // namespace emaki::pipeline
