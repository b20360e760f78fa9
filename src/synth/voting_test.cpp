// Voting: plain and error-weighted.
#include "synth/voting.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include "core/rng.h"
#include "synth/test_images.h"

namespace emaki::synth {
namespace {

using namespace test;

TEST(Voting, ShiftedFieldReproducesShiftedSource) {
  const int w = 32, h = 24, p = 5, r = 2, shift = 3;
  Image<float> src = noise(w, h, 3, 11);
  Image<int32_t> nnf(w - 2 * shift, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < nnf.width(); ++x) {
      nnf(x, y, 0) = std::clamp(x + shift, r, w - r - 1);
      nnf(x, y, 1) = std::clamp(y, r, h - r - 1);
    }
  Image<float> err(nnf.width(), h, 1), out;
  for (VoteMode mode : {VoteMode::kPlain, VoteMode::kWeighted}) {
    vote(Plane(src.cview()), nnf, err, Image<uint8_t>(), p, mode, out);
    for (int y = 2 * r; y < h - 2 * r; ++y)
      for (int x = 2 * r; x < nnf.width() - 2 * r; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(out(x, y, c), src(x + shift, y, c), 1e-6f);
  }
}

TEST(Voting, WeightedFavoursLowErrorPatches) {
  // Two source pixels values 0 and 1; pixel (2,2)'s patches all map to 0-valued pixels except
  // the patch centred on it, which maps to 1 and has zero error while the others have huge
  // error: weighted voting pulls toward 1, plain voting toward 0.
  const int w = 9, h = 9, p = 5;
  Image<float> src(w, h, 1);
  src(6, 6) = 1.0f;
  Image<int32_t> nnf(5, 5, 2);
  Image<float> err(5, 5, 1);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) {
      nnf(x, y, 0) = 2 + (x == 2 && y == 2 ? 4 : 0);
      nnf(x, y, 1) = 2 + (x == 2 && y == 2 ? 4 : 0);
      err(x, y) = (x == 2 && y == 2) ? 0.0f : 1e7f;
    }
  Image<float> plain, weighted;
  vote(Plane(src.cview()), nnf, err, Image<uint8_t>(), p, VoteMode::kPlain, plain);
  vote(Plane(src.cview()), nnf, err, Image<uint8_t>(), p, VoteMode::kWeighted, weighted);
  EXPECT_NEAR(plain(2, 2), 1.0f / 25.0f, 1e-6f);
  EXPECT_GT(weighted(2, 2), 0.9f);
}

// The vote of 3x3 and 5x5 patches sums row-wise from the patches' side. Against the per-pixel
// definition (each pixel's patches in row, then column order, double sums), every float must be
// the same: plain votes of integer and float samples, and the weighted vote at zero error (every
// weight 1), at the image's edges, with and without a target mask, 1-4 channels.
template <typename T>
Image<float> per_pixel_vote(const Image<T>& src, const Image<int32_t>& nnf,
                            const Image<uint8_t>& active, int p, double scale) {
  const int tw = nnf.width(), th = nnf.height(), nc = src.channels(), r = p / 2;
  Image<float> out(tw, th, nc);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      if (!active.empty() && !active(x, y)) continue;
      double acc[4] = {}, wsum = 0.0;
      for (int uy = std::max(0, y - r); uy <= std::min(th - 1, y + r); ++uy)
        for (int ux = std::max(0, x - r); ux <= std::min(tw - 1, x + r); ++ux) {
          if (!active.empty() && !active(ux, uy)) continue;
          const T* s = src.at(nnf(ux, uy, 0) - (ux - x), nnf(ux, uy, 1) - (uy - y));
          for (int c = 0; c < nc; ++c) acc[c] += double(s[c]);
          wsum += 1.0;
        }
      for (int c = 0; c < nc; ++c) out(x, y, c) = float(acc[c] * (scale / wsum));
    }
  return out;
}

template <typename T>
void expect_votes_equal_per_pixel_vote(double max_value, double scale) {
  CounterRng rng(5);
  const int sw = 23, sh = 19, tw = 17, th = 13;
  for (int nc = 1; nc <= 4; ++nc)
    for (int p : {3, 5, 7}) {
      const int r = p / 2;
      Image<T> src(sw, sh, nc);
      for (int y = 0; y < sh; ++y)
        for (int x = 0; x < sw * nc; ++x)
          src.row(y)[x] = T(std::is_integral_v<T> ? double(rng.uniform(uint32_t(max_value) + 1))
                                                  : rng.uniform_float() * max_value);
      Image<int32_t> nnf(tw, th, 2);
      Image<uint8_t> active(tw, th, 1);
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
          nnf(x, y, 0) = r + int(rng.uniform(uint32_t(sw - 2 * r)));
          nnf(x, y, 1) = r + int(rng.uniform(uint32_t(sh - 2 * r)));
          active(x, y) = rng.uniform(4) != 0 ? 1 : 0;
        }
      const Image<uint8_t> none;
      Image<float> err(tw, th, 1), out;
      for (const Image<uint8_t>* a : {&none, static_cast<const Image<uint8_t>*>(&active)}) {
        const Image<float> want = per_pixel_vote(src, nnf, *a, p, scale);
        for (VoteMode mode : {VoteMode::kPlain, VoteMode::kWeighted}) {
          vote(Plane(src.cview()), nnf, err, *a, p, mode, out);
          for (int y = 0; y < th; ++y)
            for (int x = 0; x < tw; ++x)
              for (int c = 0; c < nc; ++c)
                ASSERT_EQ(out(x, y, c), want(x, y, c))
                    << "channels " << nc << " patch " << p << " at " << x << "," << y
                    << (a == &none ? "" : " masked")
                    << (mode == VoteMode::kPlain ? " plain" : " weighted");
        }
      }
    }
}

TEST(Voting, EqualsThePerPixelVote) {
  expect_votes_equal_per_pixel_vote<uint8_t>(255.0, 1.0 / 255.0);
  expect_votes_equal_per_pixel_vote<uint16_t>(65535.0, 1.0 / 65535.0);
  expect_votes_equal_per_pixel_vote<float>(1.0, 1.0);
}

// The dilation against the square window it stands for, looked up pixel by pixel: sparse and
// dense masks, an empty one, radii from 0 to more than the image.
TEST(Voting, DilateMaskSetsEveryPixelWithASetPixelInItsSquare) {
  CounterRng rng(11);
  for (const int density : {0, 1, 30, 400}) {
    const int w = 97, h = 61;
    Image<uint8_t> inside(w, h, 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        inside(x, y) = density > 0 && rng.uniform(1000) < uint32_t(density) ? 1 : 0;
    if (density == 1) inside(0, 0) = inside(w - 1, h - 1) = 1;  // at the corners too
    for (const int r : {0, 1, 2, 7, 40, 200}) {
      const Image<uint8_t> out = dilate_mask(inside, r);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          uint8_t want = 0;
          for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
            for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u)
              want |= inside(u, v) ? 1 : 0;
          ASSERT_EQ(out(x, y), want)
              << "density " << density << " radius " << r << " at " << x << "," << y;
        }
    }
  }
}

}  // namespace
}  // namespace emaki::synth
