// coherent_field(): the carried field's offsets snapped to the most common one around each pixel.
#include "temporal/coherent_field.h"

#include <gtest/gtest.h>

#include <random>
#include <utility>
#include <vector>

#include "core/parallel.h"

namespace emaki::temporal {
namespace {

constexpr int kW = 40, kH = 30;

// Every pixel at (x + 100, y + 50), but every sixth row shifted by one pixel: the steps a carried
// field takes when the surface turns on screen.
Image<int32_t> staircase() {
  Image<int32_t> f(kW, kH, 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      f(x, y, 0) = x + 100 + (y % 6 == 0 ? 1 : 0);
      f(x, y, 1) = y + 50;
    }
  return f;
}

TEST(CoherentField, SnapsAStaircaseToOneOffset) {
  const Image<int32_t> out = coherent_field(staircase().cview(), 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ASSERT_EQ(out(x, y, 0), x + 100) << x << "," << y;
      ASSERT_EQ(out(x, y, 1), y + 50) << x << "," << y;
    }
}

TEST(CoherentField, KeepsACoherentFieldAndItsPieces) {
  // Two pieces side by side, each wider than the window: every pixel keeps its own offset.
  Image<int32_t> f(kW, kH, 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      f(x, y, 0) = x < 20 ? x + 3 : x + 200;
      f(x, y, 1) = x < 20 ? y + 7 : y - 4;
    }
  const Image<int32_t> out = coherent_field(f.cview(), 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ASSERT_EQ(out(x, y, 0), f(x, y, 0));
      ASSERT_EQ(out(x, y, 1), f(x, y, 1));
    }
}

TEST(CoherentField, RadiusZeroChangesNothing) {
  const Image<int32_t> f = staircase();
  const Image<int32_t> out = coherent_field(f.cview(), 0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_EQ(out(x, y, 0), f(x, y, 0));
}

TEST(CoherentField, PixelsWithoutAPatchStayAndDoNotVote) {
  Image<int32_t> f = staircase();
  // A hole of (-1, -1) entries over rows 12-15, columns 8-12: its pixels stay empty, and
  // (10, 11), whose 3x3 window is one third hole, keeps the offset the rest of its window has.
  for (int y = 12; y < 16; ++y)
    for (int x = 8; x < 13; ++x) f(x, y, 0) = f(x, y, 1) = -1;
  const Image<int32_t> out = coherent_field(f.cview(), 1);
  EXPECT_EQ(out(10, 13, 0), -1);
  EXPECT_EQ(out(10, 13, 1), -1);
  EXPECT_EQ(out(10, 12, 0), -1);
  EXPECT_EQ(out(10, 11, 0), 110);
}

TEST(CoherentField, TiesKeepTheOwnOffset) {
  // Two columns, each its own offset: every 3x3 window, cut by the border, holds as many pixels
  // of each, so every pixel keeps its own.
  Image<int32_t> f(2, 3, 2);
  for (int y = 0; y < 3; ++y) {
    f(0, y, 0) = 10, f(1, y, 0) = 41;
    f(0, y, 1) = f(1, y, 1) = y;
  }
  const Image<int32_t> out = coherent_field(f.cview(), 1);
  for (int y = 0; y < 3; ++y) {
    EXPECT_EQ(out(0, y, 0), 10);
    EXPECT_EQ(out(1, y, 0), 41);
  }
}

// The header's definition, pixel by pixel and window by window, with nothing shared between
// pixels: what the sliding counts of coherent_field() must give.
Image<int32_t> by_definition(const Image<int32_t>& f, int r) {
  Image<int32_t> out = f.clone();
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) {
      if (f(x, y, 0) < 0) continue;
      const std::pair<int, int> own{f(x, y, 0) - x, f(x, y, 1) - y};
      std::vector<std::pair<std::pair<int, int>, int>> met;  // offsets in row order, counts
      for (int yy = std::max(0, y - r); yy <= std::min(f.height() - 1, y + r); ++yy)
        for (int xx = std::max(0, x - r); xx <= std::min(f.width() - 1, x + r); ++xx) {
          if (f(xx, yy, 0) < 0) continue;
          const std::pair<int, int> o{f(xx, yy, 0) - xx, f(xx, yy, 1) - yy};
          bool found = false;
          for (auto& m : met)
            if (m.first == o) ++m.second, found = true;
          if (!found) met.push_back({o, 1});
        }
      std::pair<int, int> best = own;
      int best_count = 0;
      for (const auto& m : met)
        if (m.first == own) best_count = m.second;
      for (const auto& m : met)
        if (m.second > best_count) best = m.first, best_count = m.second;
      out(x, y, 0) = x + best.first;
      out(x, y, 1) = y + best.second;
    }
  return out;
}

// Random fields of pieces (runs of one offset along rows, some continued from the row above),
// pixels without a patch among them, at several radii: the same as the definition everywhere.
TEST(CoherentField, MatchesItsDefinitionOnRandomFields) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 24; ++trial) {
    const int w = 23 + trial * 3, h = 17 + trial * 2, r = 1 + trial % 6;
    Image<int32_t> f(w, h, 2);
    int dx = 0, dy = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const unsigned roll = rng() % 100;
        if (roll < 8) {
          f(x, y, 0) = -1;
          f(x, y, 1) = -1;
          continue;
        }
        if (roll < 30) {
          dx = int(rng() % 5) - 2;
          dy = int(rng() % 5) - 2;
        } else if (roll < 45 && y > 0 && f(x, y - 1, 0) >= 0) {
          dx = f(x, y - 1, 0) - x;
          dy = f(x, y - 1, 1) - (y - 1);
        }
        f(x, y, 0) = x + 50 + dx;
        f(x, y, 1) = y + 50 + dy;
      }
    const Image<int32_t> want = by_definition(f, r), got = coherent_field(f.cview(), r);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        ASSERT_EQ(got(x, y, 0), want(x, y, 0)) << trial << ": " << x << "," << y;
        ASSERT_EQ(got(x, y, 1), want(x, y, 1)) << trial << ": " << x << "," << y;
      }
  }
}

TEST(CoherentField, SameResultWithOneThread) {
  Image<int32_t> f(kW, kH, 2);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      f(x, y, 0) = x + (x * 7 + y * 13) % 3;  // noisy offsets: many ties and changes
      f(x, y, 1) = y + (x * 5 + y * 3) % 2;
    }
  const Image<int32_t> many = coherent_field(f.cview(), 2);
  Image<int32_t> one;
  {
    ScopedThreadCount single(1);
    one = coherent_field(f.cview(), 2);
  }
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      ASSERT_EQ(one(x, y, 0), many(x, y, 0));
      ASSERT_EQ(one(x, y, 1), many(x, y, 1));
    }
}

}  // namespace
}  // namespace emaki::temporal
