// Feature images and the image pyramid.
//
// A feature pixel interleaves the style channels then the guide channels as int16, padded with a
// zero channel to an even count so that a patch row is a whole number of int16 pairs (the
// distance kernels' 32-bit lanes; they read a row's partial last vector without passing its end).
// A multiple of 8, for whole 128-bit vectors, gave FaceStyle's 10 channels 16 and its synthesis a
// peak RSS of 107 MB instead of 85. Each channel is mapped q = round((v - lo) * mult) with
// mult = 16383 * sqrt(w / w_max) / range, so the squared difference of q values is the weighted
// squared difference of v, up to one global factor (err_scale) — weights cost nothing in the
// distance kernel.
//
// Pyramid levels halve with a [1 3 3 1] / 8 low-pass filter (EbSynth samples bilinearly without
// a low-pass, which lets thin lines alias away at coarse levels).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace emaki::synth {

inline constexpr int kQuantMax = 16383;

struct ChannelMap {
  float lo = 0.0f;    // value mapped to 0
  float mult = 0.0f;  // levels per unit of value
  int16_t quantize(float v) const {
    float q = (v - lo) * mult + 0.5f;
    q = q < 0.0f ? 0.0f : (q > float(kQuantMax) ? float(kQuantMax) : q);
    return int16_t(q);
  }
};

// Channels of a feature pixel holding n channels: n rounded up to an even count.
inline int padded_channels(int n) {
  return (n + 1) / 2 * 2;
}

struct FeatureLayout {
  int style_channels = 0;
  int guide_channels = 0;
  int channels = 0;             // padded_channels(style + guide channels)
  std::vector<ChannelMap> map;  // style then guide channels
  // EbSynth error = err_scale * distance: the sum of squared q differences, or with weight
  // maps that sum weighted per channel group in units of 1 / kGroupWeightOne.
  double err_scale = 1.0;
  // Channel groups: 1 without weight maps; else group 0 holds the channels without a map and
  // group k the channels of the k-th guide with one. group_of: per (padded) channel;
  // group_masks: the grouped kernel's masks, one row of patch_size x channels elements per
  // group, -1 where the element is in the group.
  int groups = 1;
  std::vector<int> group_of;
  std::vector<int16_t> group_masks;
};

// Output size of one halving step.
inline int half_size(int n) {
  return (n + 1) / 2;
}

// Low-pass and halve (any channel count). Integer types round to nearest.
Image<float> downsample(ImageView<const float> in);
Image<int16_t> downsample(ImageView<const int16_t> in);
// Halves by taking every other pixel, for channels [c0, c1) of `out` (already low-passed
// everywhere else). Used for the style exemplar: a low-passed exemplar has less texture
// contrast, so coarse levels would prefer its flattest regions and wash the result out.
template <typename T>
void decimate_channels(ImageView<const T> in, Image<T>& out, int c0, int c1) {
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = c0; c < c1; ++c)
        out(x, y, c) = in(std::min(2 * x, in.width - 1), std::min(2 * y, in.height - 1), c);
}
// A mask halves to "any child inside".
Image<uint8_t> downsample_mask(ImageView<const uint8_t> in);

// Fills the `border`-pixel frame of an image from its interior (clamp to edge), for channels
// [c0, c1).
void pad_replicate(Image<int16_t>& padded, int border, int c0, int c1);

// The interior view of a padded image.
template <typename T>
ImageView<T> interior(Image<T>& padded, int border) {
  auto v = padded.view();
  return {v.at(border, border), v.width - 2 * border, v.height - 2 * border, v.channels, v.stride};
}
template <typename T>
ImageView<const T> interior(const Image<T>& padded, int border) {
  auto v = padded.view();
  return {v.at(border, border), v.width - 2 * border, v.height - 2 * border, v.channels, v.stride};
}

}  // namespace emaki::synth
