// Voting: plain and error-weighted.
#include "synth/voting.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
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

// The plain vote of integer samples sums row-wise from the patches' side; the weighted vote at
// zero error (every weight 1) still gathers per pixel in doubles. Both must give the same floats,
// at the image's edges, with a target mask, for 1-4 channels and every patch size.
template <typename T>
void expect_plain_equals_unit_weighted(int max_value) {
  CounterRng rng(5);
  const int sw = 23, sh = 19, tw = 17, th = 13;
  for (int nc = 1; nc <= 4; ++nc)
    for (int p : {3, 5, 7}) {
      const int r = p / 2;
      Image<T> src(sw, sh, nc);
      for (int y = 0; y < sh; ++y)
        for (int x = 0; x < sw * nc; ++x) src.row(y)[x] = T(rng.uniform(uint32_t(max_value + 1)));
      Image<int32_t> nnf(tw, th, 2);
      Image<uint8_t> active(tw, th, 1);
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
          nnf(x, y, 0) = r + int(rng.uniform(uint32_t(sw - 2 * r)));
          nnf(x, y, 1) = r + int(rng.uniform(uint32_t(sh - 2 * r)));
          active(x, y) = rng.uniform(4) != 0 ? 1 : 0;
        }
      Image<float> err(tw, th, 1), plain, weighted;
      for (const Image<uint8_t>* mask : {static_cast<const Image<uint8_t>*>(&active),
                                         static_cast<const Image<uint8_t>*>(nullptr)}) {
        const Image<uint8_t> none;
        const Image<uint8_t>& a = mask ? *mask : none;
        vote(Plane(src.cview()), nnf, err, a, p, VoteMode::kPlain, plain);
        vote(Plane(src.cview()), nnf, err, a, p, VoteMode::kWeighted, weighted);
        for (int y = 0; y < th; ++y)
          for (int x = 0; x < tw; ++x)
            for (int c = 0; c < nc; ++c)
              ASSERT_EQ(plain(x, y, c), weighted(x, y, c))
                  << "channels " << nc << " patch " << p << " at " << x << "," << y
                  << (mask ? " masked" : "");
      }
    }
}

TEST(Voting, PlainIntegerVoteEqualsUnitWeightedVote) {
  expect_plain_equals_unit_weighted<uint8_t>(255);
  expect_plain_equals_unit_weighted<uint16_t>(65535);
}

}  // namespace
}  // namespace emaki::synth
