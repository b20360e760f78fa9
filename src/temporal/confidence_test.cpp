// The advection's confidence: a square (object 2) moves 6 pixels right over a static ground
// (object 1); the ground it uncovers was hidden at t-1 and must get no confidence.
#include "temporal/confidence.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "temporal/advection.h"

namespace emaki::temporal {
namespace {

constexpr int kW = 64, kH = 48, kShift = 6, kX0 = 20, kX1 = 36, kY0 = 14, kY1 = 34;

// Rest position + id of the frame where the square's left edge is at x0.
Image<float> surface(int x0) {
  Image<float> s(kW, kH, 4);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool square = x >= x0 && x < x0 + (kX1 - kX0) && y >= kY0 && y < kY1;
      float* p = s.at(x, y);
      if (square) {
        p[0] = 0.5f + 0.01f * (x - x0), p[1] = 0.2f + 0.01f * (y - kY0), p[2] = 0.9f, p[3] = 2;
      } else {
        p[0] = float(x) / kW, p[1] = 0.0f, p[2] = float(y) / kH, p[3] = 1;
      }
    }
  return s;
}

// Motion from t (square at kX0 + kShift) back to t-1 (square at kX0).
Image<float> motion() {
  Image<float> m(kW, kH, 2);
  for (int y = kY0; y < kY1; ++y)
    for (int x = kX0 + kShift; x < kX1 + kShift; ++x) m(x, y, 0) = -float(kShift);
  return m;
}

bool uncovered(int x, int y) {
  return x >= kX0 && x < kX0 + kShift && y >= kY0 && y < kY1;
}

struct Scene {
  Image<float> prev = surface(kX0), cur = surface(kX0 + kShift), mot = motion();
  Surfaces surfaces() const { return {prev.cview(), cur.cview(), mot.cview()}; }
};

TEST(Confidence, UncoveredGroundWasNotVisible) {
  const Scene s;
  const Image<uint8_t> v = visible_before(s.surfaces());
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) EXPECT_EQ(v(x, y), uncovered(x, y) ? 0 : 1) << x << "," << y;
}

// The same object in front of itself: ids agree, rest positions do not.
TEST(Confidence, SelfCoverIsSeenByRestPosition) {
  Scene s;
  for (int y = kY0; y < kY1; ++y)
    for (int x = kX0; x < kX0 + kShift; ++x) s.prev(x, y, 3) = 1;  // the square is ground too
  const Image<uint8_t> v = visible_before(s.surfaces());
  EXPECT_EQ(v(kX0 + 2, kY0 + 5), 0);
  EXPECT_EQ(v(kX0 - 5, kY0 + 5), 1);
}

TEST(Confidence, OutsideTheFrameWasNotVisible) {
  Scene s;
  for (int y = 0; y < kH; ++y) s.mot(0, y, 0) = -3.0f;
  const Image<uint8_t> v = visible_before(s.surfaces());
  EXPECT_EQ(v(0, 3), 0);
  EXPECT_EQ(v(1, 3), 1);
}

// The square's patches follow its motion, the ground's stay: the uncovered strip reads the
// square that covered it at t-1, and next to the square some of a pixel's patches do too.
TEST(Confidence, ForeignShareCountsVotesFromAnotherObject) {
  const Scene s;
  Image<int32_t> nnf(kW, kH, 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      nnf(x, y, 0) = std::clamp(x + int(s.mot(x, y, 0)), 2, kW - 3);
      nnf(x, y, 1) = y;
    }
  const Image<float> f = foreign_share(nnf, s.surfaces(), 5, 0);
  EXPECT_EQ(f(kX0 + 2, kY0 + 8), 1.0f);  // inside the uncovered strip: the square at t-1
  EXPECT_EQ(f(5, 5), 0.0f);
  EXPECT_EQ(f(kX0 + kShift + 4, kY0 + 8), 0.0f);  // the square, carried along
  // The strip's last column: the two patches centred on the square read ground 6 px left.
  EXPECT_FLOAT_EQ(f(kX0 + kShift - 1, kY0 + 8), 15.0f / 25.0f);
  // With the footprint of t-1's own patches: ground just left of the square at t-1 (which
  // stays put) was voted by patches centred on the square too, 2 columns of 5.
  const Image<float> g = foreign_share(nnf, s.surfaces(), 5, 2);
  EXPECT_EQ(f(kX0 - 1, kY0 + 8), 0.0f);
  EXPECT_FLOAT_EQ(g(kX0 - 1, kY0 + 8), 0.4f);
  EXPECT_EQ(g(5, 5), 0.0f);
}

// Over a mask, from shared id shares: the same, bit for bit, as the field with -1 outside the
// mask.
TEST(Confidence, ForeignShareOverAMaskIsTheMaskedFields) {
  const Scene s;
  Image<int32_t> nnf(kW, kH, 2), masked(kW, kH, 2);
  Image<uint8_t> active(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      nnf(x, y, 0) = std::clamp(x + int(s.mot(x, y, 0)) + (x * 7 + y * 3) % 5 - 2, 2, kW - 3);
      nnf(x, y, 1) = std::clamp(y + (x * 5 + y) % 3 - 1, 2, kH - 3);
      active(x, y) = (x - 30) * (x - 30) + (y - 22) * (y - 22) < 150 ? 1 : 0;
      masked(x, y, 0) = active(x, y) ? nnf(x, y, 0) : -1;
      masked(x, y, 1) = active(x, y) ? nnf(x, y, 1) : -1;
    }
  const IdShares shares = id_shares(s.prev.cview(), 2);
  const Image<float> expected = foreign_share(masked, s.surfaces(), 5, 2);
  const Image<float> got = foreign_share(nnf, active, s.surfaces(), 5, shares);
  int inside = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      EXPECT_EQ(got(x, y), expected(x, y)) << x << "," << y;
      inside += expected(x, y) > 0.0f ? 1 : 0;
    }
  EXPECT_GT(inside, 0);
}

// id_shares against its definition written pixel by pixel (the share of the clamped window's
// pixels showing each id: the mean over the window's rows, from the top, of each row's share),
// bit for bit: objects of every size, at the borders, one of a single pixel, at radii 0-4.
TEST(Confidence, IdSharesAreTheWindowMeansOfEachId) {
  const int w = 41, h = 29;
  Image<float> ids(w, h, 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float k = 0.0f;
      if (x < 6 && y > 20) k = 3.0f;                                 // a corner
      if ((x - 20) * (x - 20) + (y - 12) * (y - 12) < 40) k = 7.0f;  // a disc
      if (x > 30 && (x + y) % 3 == 0) k = 5.0f;                      // stripes at the edge
      if (x == 12 && y == 3) k = 9.0f;                               // one pixel
      ids(x, y, 3) = k;
    }
  for (int radius = 0; radius <= 4; ++radius) {
    const IdShares s = id_shares(ids.cview(), radius);
    ASSERT_EQ(s.ids, (std::vector<float>{0.0f, 5.0f, 9.0f, 7.0f, 3.0f})) << radius;
    for (std::size_t i = 0; i < s.ids.size(); ++i)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          float sum = 0.0f;
          int rows = 0;
          for (int v = std::max(0, y - radius); v <= std::min(h - 1, y + radius); ++v, ++rows) {
            int n = 0, hit = 0;
            for (int u = std::max(0, x - radius); u <= std::min(w - 1, x + radius); ++u)
              ++n, hit += ids(u, v, 3) == s.ids[i] ? 1 : 0;
            sum += float(hit) / float(n);
          }
          ASSERT_EQ(s.share[i](x, y), sum / float(rows))
              << "id " << s.ids[i] << " radius " << radius << " at " << x << "," << y;
        }
  }
}

TEST(Confidence, ErrorRampAndErosion) {
  Image<uint8_t> visible(9, 1, 1);
  Image<float> foreign(9, 1, 1), error(9, 1, 1);
  visible.fill(1);
  visible(0, 0) = 0;
  foreign(1, 0) = 0.25f;
  ConfidenceParams cp;
  cp.erode = 0;
  const float rms_to_error = 65025.0f * 9.0f;  // patch 3
  error(2, 0) = cp.error_full * cp.error_full * rms_to_error;
  const float mid = 0.5f * (cp.error_full + cp.error_none);
  error(3, 0) = mid * mid * rms_to_error;
  error(4, 0) = cp.error_none * cp.error_none * rms_to_error;
  const Image<float> c = confidence(visible, foreign, error, 3, cp);
  EXPECT_EQ(c(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(c(1, 0), 0.75f);
  EXPECT_NEAR(c(2, 0), 1.0f, 1e-5f);
  EXPECT_NEAR(c(3, 0), 0.5f, 1e-4f);
  EXPECT_NEAR(c(4, 0), 0.0f, 1e-5f);
  EXPECT_EQ(c(8, 0), 1.0f);
  cp.erode = 1;
  const Image<float> e = confidence(visible, foreign, error, 3, cp);
  EXPECT_NEAR(e(5, 0), 0.0f, 1e-5f);  // next to pixel 4
  EXPECT_EQ(e(6, 0), 1.0f);
}

// Through the advection: no confidence on the uncovered strip, full confidence on the ground
// away from the square and on the square itself.
TEST(Confidence, AdvectionGivesNoneWhereTheSurfaceWasHidden) {
  const Scene s;
  Image<float> prev(kW, kH, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) prev(x, y) = s.prev(x, y, 3) == 2 ? 0.1f : 0.9f;
  AdvectionInputs in;
  in.previous_stylized = prev.cview();
  in.previous_guide = s.prev.cview();
  in.current_guide = s.cur.cview();
  in.surfaces = s.surfaces();
  const Advection a = advect(in, synth::Params{});
  ASSERT_FALSE(a.confidence.empty());
  for (int y = kY0 + 1; y < kY1 - 1; ++y)
    for (int x = kX0; x < kX0 + kShift; ++x) EXPECT_EQ(a.confidence(x, y), 0.0f) << x << "," << y;
  EXPECT_GT(a.confidence(5, 5), 0.99f);
  EXPECT_GT(a.confidence(kX0 + kShift + 8, kY0 + 10), 0.99f);
}

}  // namespace
}  // namespace emaki::temporal
