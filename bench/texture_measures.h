// What flicker, ghosts and the judge miss in a temporal chain, measured against frame by frame
// of the same shot on the same pixels (temporal_bench):
// - tone drift: the mean level of the layer inside its mask, temporal minus frame by frame, in
//   levels of 255 (a chain whose ink fades or whose strokes thin out turns positive);
// - texture kept: the high-pass energy (each value minus the mean of the 5 x 5 box around it,
//   squared) of the temporal result over frame by frame's, same pixels (a chain that settles
//   into flat regions falls below 1);
// - wash: the same two figures over the pixels whose surface was hidden at some frame of the
//   last `kWashFrames` (disoccluded, tracked along the motion vectors): behind a moving object
//   the temporal result should look like frame by frame, not a pale, untextured wash.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/image.h"
#include "pipeline/frames.h"
#include "pipeline/temporal_guide.h"
#include "render/passes.h"
#include "temporal/confidence.h"
#include "temporal/guide_change.h"

namespace emaki::bench {

// Frames a disoccluded pixel counts in the wash measure.
inline constexpr int kWashFrames = 4;

struct ToneTexture {
  double level_sum = 0.0, reference_level_sum = 0.0;  // values in [0, 1]
  double energy = 0.0, reference_energy = 0.0;
  long pixels = 0;
  double drift_levels() const {
    return pixels ? 255.0 * (level_sum - reference_level_sum) / double(pixels) : 0.0;
  }
  double texture_kept() const { return reference_energy > 0 ? energy / reference_energy : 0.0; }
  // One pixel: its level and high-pass value, temporal and frame by frame.
  void add(float level, float reference_level, float high, float reference_high) {
    level_sum += level, reference_level_sum += reference_level;
    energy += double(high) * high, reference_energy += double(reference_high) * reference_high;
    ++pixels;
  }
};

// v minus the mean of the (2r+1)^2 box around it (clamped at the borders), channel 0.
inline Image<float> high_pass(const Image<float>& v, int r = 2) {
  const int w = v.width(), h = v.height();
  Image<double> integral(w + 1, h + 1, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      integral(x + 1, y + 1) =
          v(x, y, 0) + integral(x, y + 1) + integral(x + 1, y) - integral(x, y);
  Image<float> out(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int x0 = std::max(0, x - r), x1 = std::min(w, x + r + 1);
      const int y0 = std::max(0, y - r), y1 = std::min(h, y + r + 1);
      const double s = integral(x1, y1) - integral(x0, y1) - integral(x1, y0) + integral(x0, y0);
      out(x, y) = float(v(x, y, 0) - s / double((x1 - x0) * (y1 - y0)));
    }
  return out;
}

// Adds frame f's figures over the pixels inside `mask_channel` of `value` (every pixel for -1)
// where `select` (may be empty) is non-zero. `value`, `reference`: the layer's frames over white
// outside the mask (channel 0 is used), `raw`: the temporal frame with its coverage.
inline void add_tone_texture(ToneTexture& t, const Image<float>& value,
                             const Image<float>& reference, const Image<float>& raw,
                             int mask_channel, const Image<uint8_t>& select) {
  const Image<float> hv = high_pass(value), hr = high_pass(reference);
  for (int y = 0; y < value.height(); ++y)
    for (int x = 0; x < value.width(); ++x) {
      if (mask_channel >= 0 && raw(x, y, mask_channel) < 0.5f) continue;
      if (!select.empty() && !select(x, y)) continue;
      t.add(value(x, y, 0), reference(x, y, 0), hv(x, y), hr(x, y));
    }
}

// add_tone_texture() per object: each pixel inside the mask counts for the object id its passes
// give it (1: the ground; the background, alpha 0, is left out).
inline void add_tone_texture_by_object(std::map<int, ToneTexture>& by_id, const Image<float>& value,
                                       const Image<float>& reference, const Image<float>& raw,
                                       int mask_channel, ImageView<const float> passes) {
  const Image<float> hv = high_pass(value), hr = high_pass(reference);
  for (int y = 0; y < value.height(); ++y)
    for (int x = 0; x < value.width(); ++x) {
      if (mask_channel >= 0 && raw(x, y, mask_channel) < 0.5f) continue;
      const float* p = passes.at(x, y);
      if (p[render::kAlpha] <= 0.5f) continue;
      by_id[int(std::lround(p[render::kObjectId]))].add(value(x, y, 0), reference(x, y, 0),
                                                        hv(x, y), hr(x, y));
    }
}

// The pixel of t-1 that pixel (x, y) of t comes from: the end of its motion vector, rounded (it
// may lie outside the image).
struct Pixel {
  int x = 0, y = 0;
};
inline Pixel motion_source(ImageView<const float> passes, int x, int y) {
  const float* p = passes.at(x, y);
  return {int(std::lround(x + p[render::kMotion])), int(std::lround(y + p[render::kMotion + 1]))};
}

// Frame t-1 carried to t along the motion vectors in whole pixels (each pixel takes the pixel of
// t-1 its motion points to, rounded; clamped to the image): a picture stuck to its surfaces as a
// chain that carries whole pixels would at best keep it. Its flicker against t-1 is the least such
// a chain can score with that picture's texture (the measure samples t-1 between pixels).
inline Image<float> carried_whole_pixels(const Image<float>& previous,
                                         ImageView<const float> passes) {
  const int w = previous.width(), h = previous.height();
  Image<float> out(w, h, previous.channels());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Pixel q = motion_source(passes, x, y);
      const int sx = std::clamp(q.x, 0, w - 1), sy = std::clamp(q.y, 0, h - 1);
      for (int c = 0; c < previous.channels(); ++c) out(x, y, c) = previous(sx, sy, c);
    }
  return out;
}

// The first `n` channels of a layer's value low-passed by a Gaussian of `sigma` pixels inside
// its coverage (channel n, when it has one), the coverage kept. The flicker measure on such
// values compares frames at the scale of the painting's touches: a picture moved by a fraction
// of a pixel differs far less from t-1 sampled between pixels than at full detail (the `stuck`
// figure), while a touch that changes still does.
inline Image<float> low_passed_value(const Image<float>& v, int n, float sigma) {
  const int w = v.width(), h = v.height();
  Image<float> value(w, h, n), mask;
  if (v.channels() > n) mask = Image<float>(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < n; ++c) value(x, y, c) = v(x, y, c);
      if (!mask.empty()) mask(x, y, 0) = v(x, y, n) >= 0.5f ? 1.0f : 0.0f;
    }
  const Image<float> low = temporal::low_pass(value.cview(), sigma, mask.cview());
  Image<float> out = v.clone();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < n; ++c) out(x, y, c) = low(x, y, c);
  return out;
}

// Where the light on the surface held between t-1 and t: each channel of the layer's guides
// other than the normals (`current`, `previous`: pipeline::change_guides()) differs by at most
// `tolerance` from its value at the pixel of t-1 the motion vectors point to, at the pixel and at
// every pixel within `reach` of it (a square cut by the image's border): a pixel's value comes
// from the patches over it, each matched on its guides, so a change of light reaches
// patch_size - 1 pixels further. The flicker there is the chain's own; elsewhere a moving light,
// shadow or silhouette changes what the painting gives.
inline Image<uint8_t> light_held(const Image<float>& current, const Image<float>& previous,
                                 ImageView<const float> passes, float tolerance, int reach = 0) {
  const int w = current.width(), h = current.height();
  Image<uint8_t> out(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto [sx, sy] = motion_source(passes, x, y);
      if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
      bool held = true;
      for (int c = 0; c < current.channels() && held; ++c)
        held = std::abs(current(x, y, c) - previous(sx, sy, c)) <= tolerance;
      out(x, y) = held;
    }
  if (reach <= 0) return out;
  // The minimum over the square, along rows then along columns. A pixel whose motion leaves the
  // image counts as not held for its neighbours too.
  const auto min_along = [&](const Image<uint8_t>& in, int dx, int dy) {
    Image<uint8_t> m(w, h, 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t v = 1;
        for (int k = -reach; k <= reach && v; ++k) {
          const int xx = x + k * dx, yy = y + k * dy;
          if (xx >= 0 && yy >= 0 && xx < w && yy < h) v = in(xx, yy);
        }
        m(x, y) = v;
      }
    return m;
  };
  return min_along(min_along(out, 1, 0), 0, 1);
}

// Frames since each pixel's surface was last hidden (0: hidden at t-1), carried along the motion
// vectors from the previous frame's ages. Start with an empty `age` (everything old).
inline void update_disocclusion_age(Image<uint8_t>& age, ImageView<const float> passes,
                                    ImageView<const float> prev_passes) {
  const Image<float> cur =
      pipeline::advection_guide(passes, pipeline::AdvectionGuide::kRestPosition);
  const Image<float> prev =
      pipeline::advection_guide(prev_passes, pipeline::AdvectionGuide::kRestPosition);
  const Image<float> motion = pipeline::extract(passes, render::kMotion, 2);
  const Image<uint8_t> visible =
      temporal::visible_before({prev.cview(), cur.cview(), motion.cview()});
  const int w = passes.width, h = passes.height;
  Image<uint8_t> next(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto [sx, sy] = motion_source(passes, x, y);
      const bool inside = sx >= 0 && sy >= 0 && sx < w && sy < h;
      const int before = age.empty() || !inside ? 255 : age(sx, sy);
      next(x, y) = visible(x, y) ? uint8_t(std::min(255, before + 1)) : 0;
    }
  age = std::move(next);
}

// The pixels disoccluded within the last kWashFrames frames, covered by an object.
inline Image<uint8_t> recently_disoccluded(const Image<uint8_t>& age,
                                           ImageView<const float> passes) {
  Image<uint8_t> out(age.width(), age.height(), 1);
  for (int y = 0; y < age.height(); ++y)
    for (int x = 0; x < age.width(); ++x)
      out(x, y) = age(x, y) < kWashFrames && passes.at(x, y)[render::kAlpha] >= 1.0f &&
                  passes.at(x, y)[render::kOutline] <= 0.0f;
  return out;
}

// The mean of every channel of every pixel.
inline double mean_value(const Image<float>& v) {
  double sum = 0.0;
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x)
      for (int c = 0; c < v.channels(); ++c) sum += v(x, y, c);
  return sum / (double(v.width()) * v.height() * v.channels());
}

// Frame f's ink: one line of "ink F VARIANT PIXELS INK FRAME_INK G1 ... FRAME_G1 ...": the mean of
// one minus the layer's value over its mask (INK) and over the whole frame, white outside the mask
// (FRAME_INK), then the mean of each guide's first channel over the mask, then over the frame.
inline void print_ink(std::FILE* out, int f, const char* variant, const Image<float>& raw,
                      int mask_channel, const std::vector<Image<float>>& guides) {
  double ink = 0.0, frame_ink = 0.0;
  std::vector<double> g(guides.size()), fg(guides.size());
  long pixels = 0;
  for (int y = 0; y < raw.height(); ++y)
    for (int x = 0; x < raw.width(); ++x) {
      const bool in = mask_channel < 0 || raw(x, y, mask_channel) >= 0.5f;
      const float a = mask_channel < 0 ? 1.0f : raw(x, y, mask_channel);
      frame_ink += a * (1.0 - raw(x, y, 0));
      for (std::size_t i = 0; i < guides.size(); ++i) fg[i] += guides[i](x, y, 0);
      if (!in) continue;
      ++pixels;
      ink += 1.0 - raw(x, y, 0);
      for (std::size_t i = 0; i < guides.size(); ++i) g[i] += guides[i](x, y, 0);
    }
  const double n = double(raw.width()) * raw.height(), m = std::max(1L, pixels);
  std::fprintf(out, "ink %d %s %ld %.6f %.6f", f, variant, pixels, ink / m, frame_ink / n);
  for (double v : g) std::fprintf(out, " %.6f", v / m);
  for (double v : fg) std::fprintf(out, " %.6f", v / n);
  std::fprintf(out, "\n");
}

// print_ink() of every frame first..last of every variant (`names`; read(i, f): variant i's
// frame f).
template <class Read>
void print_inks(const pipeline::FrameSource& source, const pipeline::Layer& layer, int first,
                int last, const std::vector<std::string>& names, Read read) {
  for (int f = first; f <= last; ++f) {
    const Image<float> passes = source.passes(f);
    std::vector<Image<float>> guides;
    for (const pipeline::GuideSpec& g : layer.guides)
      guides.push_back(pipeline::extract_pass(passes.cview(), g.pass));
    for (std::size_t i = 0; i < names.size(); ++i) {
      const Image<float> raw = read(i, f);
      print_ink(stdout, f, names[i].c_str(), raw, raw.channels() > 1 ? 1 : -1, guides);
    }
  }
}

}  // namespace emaki::bench
