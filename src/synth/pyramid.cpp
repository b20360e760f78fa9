#include "synth/pyramid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/parallel.h"

namespace emaki::synth {

namespace {

template <typename T>
Image<T> downsample_impl(ImageView<const T> in) {
  const int w = in.width, h = in.height, c = in.channels;
  const int ow = half_size(w), oh = half_size(h);
  Image<T> out(ow, oh, c);
  // Each band of output rows: the horizontal pass of the input rows it reads, into floats the
  // band alone holds (a whole-image float buffer was twice the output of an int16 level, the
  // synthesis's peak of memory), then the vertical pass. The rows two bands share are filtered
  // by both, the same way: the result does not depend on the bands.
  parallel_rows(oh, 32, [&](int y0, int y1) {
    const int r0 = std::clamp(2 * y0 - 1, 0, h - 1), r1 = std::min(2 * (y1 - 1) + 2, h - 1);
    const std::size_t row = std::size_t(ow) * c;
    std::vector<float> tmp(std::size_t(r1 - r0 + 1) * row);
    for (int y = r0; y <= r1; ++y) {
      float* t = tmp.data() + std::size_t(y - r0) * row;
      const T* in_row = in.row(y);
      for (int x = 0; x < ow; ++x, t += c) {
        const T* p0 = in_row + std::ptrdiff_t(std::clamp(2 * x - 1, 0, w - 1)) * c;
        const T* p1 = in_row + std::ptrdiff_t(std::min(2 * x, w - 1)) * c;
        const T* p2 = in_row + std::ptrdiff_t(std::min(2 * x + 1, w - 1)) * c;
        const T* p3 = in_row + std::ptrdiff_t(std::min(2 * x + 2, w - 1)) * c;
        for (int k = 0; k < c; ++k)
          t[k] = (float(p0[k]) + 3.0f * float(p1[k]) + 3.0f * float(p2[k]) + float(p3[k])) * 0.125f;
      }
    }
    for (int y = y0; y < y1; ++y) {
      const auto tmp_row = [&](int ry) { return tmp.data() + std::size_t(ry - r0) * row; };
      const float* q0 = tmp_row(std::clamp(2 * y - 1, 0, h - 1));
      const float* q1 = tmp_row(std::min(2 * y, h - 1));
      const float* q2 = tmp_row(std::min(2 * y + 1, h - 1));
      const float* q3 = tmp_row(std::min(2 * y + 2, h - 1));
      T* o = out.row(y);
      for (std::size_t i = 0; i < row; ++i) {
        const float v = (q0[i] + 3.0f * q1[i] + 3.0f * q2[i] + q3[i]) * 0.125f;
        if constexpr (std::is_integral_v<T>) {
          // std::lround's halves away from zero, exact in double, without the call.
          const double d = double(v);
          o[i] = T(int64_t(d + (d >= 0.0 ? 0.5 : -0.5)));
        } else {
          o[i] = v;
        }
      }
    }
  });
  return out;
}

}  // namespace

Image<float> downsample(ImageView<const float> in) {
  return downsample_impl(in);
}
Image<int16_t> downsample(ImageView<const int16_t> in) {
  return downsample_impl(in);
}

Image<uint8_t> downsample_mask(ImageView<const uint8_t> in) {
  const int ow = half_size(in.width), oh = half_size(in.height);
  Image<uint8_t> out(ow, oh, 1);
  for (int y = 0; y < oh; ++y)
    for (int x = 0; x < ow; ++x) {
      uint8_t v = 0;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx)
          v |= in(std::min(2 * x + dx, in.width - 1), std::min(2 * y + dy, in.height - 1));
      out(x, y) = v;
    }
  return out;
}

void pad_replicate(Image<int16_t>& im, int b, int c0, int c1) {
  const int w = im.width() - 2 * b, h = im.height() - 2 * b;
  for (int y = 0; y < im.height(); ++y) {
    const int sy = std::clamp(y, b, b + h - 1);
    for (int x = 0; x < im.width(); ++x) {
      if (y >= b && y < b + h && x >= b && x < b + w) {
        x = b + w - 1;  // skip the interior
        continue;
      }
      const int sx = std::clamp(x, b, b + w - 1);
      for (int k = c0; k < c1; ++k) im(x, y, k) = im(sx, sy, k);
    }
  }
}

}  // namespace emaki::synth
