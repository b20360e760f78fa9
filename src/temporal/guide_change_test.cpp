// Guide change along the advection, and the masked low-pass of the temporal guide.
#include "temporal/guide_change.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace emaki::temporal {
namespace {

constexpr int kW = 32, kH = 8;

// A shadow guide: 1 (lit) right of `edge`, 0 left of it.
Image<float> shadow(int edge) {
  Image<float> s(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) s(x, y) = x < edge ? 0.0f : 1.0f;
  return s;
}

Image<int32_t> identity_field() {
  Image<int32_t> f(kW, kH, 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) f(x, y, 0) = x, f(x, y, 1) = y;
  return f;
}

TEST(GuideChange, MarksWhereTheShadowMovedOn) {
  // The surface is still (identity field) and the shadow's edge moves from x = 10 to x = 14.
  const Image<float> prev = shadow(10), cur = shadow(14);
  const Image<float> c = guide_change(identity_field(), prev.cview(), cur.cview());
  for (int x = 0; x < kW; ++x) EXPECT_EQ(c(x, 3), x >= 10 && x < 14 ? 1.0f : 0.0f) << x;
}

TEST(GuideChange, FollowsTheFieldNotTheScreen) {
  // The surface and its shadow move 4 pixels right together: along the field nothing changed.
  Image<int32_t> f = identity_field();
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) f(x, y, 0) = std::max(0, x - 4);
  const Image<float> prev = shadow(10), cur = shadow(14);
  const Image<float> c = guide_change(f, prev.cview(), cur.cview());
  for (int x = 4; x < kW; ++x) EXPECT_EQ(c(x, 3), 0.0f) << x;
}

TEST(GuideChange, NoMatchIsAFullChange) {
  Image<int32_t> f = identity_field();
  f(5, 2, 0) = -1, f(5, 2, 1) = -1;
  const Image<float> g = shadow(10);
  EXPECT_EQ(guide_change(f, g.cview(), g.cview())(5, 2), 1.0f);
}

TEST(LowPass, KeepsAConstantAndSmoothsAnEdge) {
  const Image<float> g = shadow(16);
  const Image<float> b = low_pass(g.cview(), 2.0f);
  EXPECT_NEAR(b(2, 4), 0.0f, 1e-6f);
  EXPECT_NEAR(b(29, 4), 1.0f, 1e-6f);
  EXPECT_GT(b(15, 4), 0.2f);
  EXPECT_LT(b(16, 4), 0.8f);
}

TEST(LowPass, AMaskKeepsWhatLiesOutsideOut) {
  // A dark band 3 pixels wide (x 14-16, inside the mask) on white outside it: blurred within
  // the mask it stays dark; blurred over everything it would turn pale.
  Image<float> g(kW, kH, 1), mask(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool band = x >= 14 && x <= 16;
      g(x, y) = band ? 0.1f : 1.0f;
      mask(x, y) = band ? 1.0f : 0.0f;
    }
  const Image<float> inside = low_pass(g.cview(), 2.0f, mask.cview());
  const Image<float> everywhere = low_pass(g.cview(), 2.0f);
  EXPECT_NEAR(inside(15, 4), 0.1f, 1e-5f);
  EXPECT_NEAR(inside(3, 4), 1.0f, 1e-6f);
  EXPECT_GT(everywhere(15, 4), 0.4f);
}

// The masked low-pass is a normalised convolution: each pass sums value x weight and weight over
// the kernel's taps (borders clamped) in doubles, tap by tap in kernel order; the column pass
// weighs each row result by the mask it saw. One and three channels, to the bit.
TEST(LowPass, IsTheNormalisedConvolutionTapByTap) {
  for (const int n : {1, 3}) {
    const int w = 37, h = 23;
    const float sigma = 3.0f;
    Image<float> g(w, h, n), mask(w, h, 1);
    uint32_t state = 12345;
    const auto next = [&] {
      return float((state = state * 1664525u + 1013904223u) >> 8) / 16777216.0f;
    };
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < n; ++c) g(x, y, c) = next();
        mask(x, y) = next() < 0.7f ? 1.0f : 0.0f;
      }
    const Image<float> got = low_pass(g.cview(), sigma, mask.cview());
    const int r = int(std::ceil(3.0f * sigma));
    std::vector<float> k(std::size_t(2 * r + 1));
    for (int i = -r; i <= r; ++i)
      k[std::size_t(i + r)] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
    const auto pass = [&](const Image<float>& in, const Image<float>& in_w, Image<float>& out,
                          Image<float>& out_w, bool along_x) {
      out.reset(w, h, n);
      out_w.reset(w, h, 1);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          std::vector<double> acc(std::size_t(n), 0.0);
          double sw = 0.0;
          for (int i = -r; i <= r; ++i) {
            const int u = std::clamp(along_x ? x + i : x, 0, w - 1);
            const int v = std::clamp(along_x ? y : y + i, 0, h - 1);
            const double wt = double(k[std::size_t(i + r)]) * in_w(u, v);
            sw += wt;
            for (int c = 0; c < n; ++c) acc[std::size_t(c)] += wt * in(u, v, c);
          }
          out_w(x, y) = float(sw);
          for (int c = 0; c < n; ++c)
            out(x, y, c) = sw > 0.0 ? float(acc[std::size_t(c)] / sw) : in(x, y, c);
        }
    };
    Image<float> rows, rows_w, want, want_w;
    pass(g, mask, rows, rows_w, true);
    pass(rows, rows_w, want, want_w, false);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < n; ++c) {
          const float expect = mask(x, y) > 0.0f ? want(x, y, c) : g(x, y, c);
          ASSERT_EQ(got(x, y, c), expect) << n << " channels at " << x << "," << y;
        }
  }
}

}  // namespace
}  // namespace emaki::temporal
