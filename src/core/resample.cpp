#include "core/resample.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace emaki {

namespace {

// One axis: for output cell i, the input indices [first, first + count) and their weights
// (covered fractions, divided by the cell's width so that they sum to 1).
struct Taps {
  std::vector<int> first, count;
  std::vector<float> weight;  // count[i] weights for cell i, cells one after another
  std::vector<int> offset;    // where cell i's weights start
};

Taps taps(int in, int out) {
  Taps t;
  const double step = double(in) / out;
  for (int i = 0; i < out; ++i) {
    const double a = i * step, b = (i + 1) * step;
    const int lo = int(std::floor(a)), hi = std::min(in, int(std::ceil(b)));
    t.first.push_back(lo);
    t.count.push_back(hi - lo);
    t.offset.push_back(int(t.weight.size()));
    for (int k = lo; k < hi; ++k)
      t.weight.push_back(float((std::min(b, k + 1.0) - std::max(a, double(k))) / step));
  }
  return t;
}

}  // namespace

Image<float> resample_area(ImageView<const float> in, int width, int height) {
  CHECK(width >= 1 && height >= 1 && !in.empty());
  const int c = in.channels;
  const Taps tx = taps(in.width, width), ty = taps(in.height, height);
  // Rows first (in.height x width), then columns.
  Image<float> rows(width, in.height, c);
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < width; ++x) {
      float* o = &rows(x, y, 0);
      for (int k = 0; k < tx.count[x]; ++k) {
        const float w = tx.weight[tx.offset[x] + k];
        const float* p = in.at(tx.first[x] + k, y);
        for (int ch = 0; ch < c; ++ch) o[ch] += w * p[ch];
      }
    }
  Image<float> out(width, height, c);
  for (int y = 0; y < height; ++y)
    for (int k = 0; k < ty.count[y]; ++k) {
      const float w = ty.weight[ty.offset[y] + k];
      const int sy = ty.first[y] + k;
      for (int x = 0; x < width; ++x)
        for (int ch = 0; ch < c; ++ch) out(x, y, ch) += w * rows(x, sy, ch);
    }
  return out;
}

}  // namespace emaki
