// Planes: their sizes, value ranges and finiteness.
#include "synth/planes.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <vector>

#include "core/check.h"
#include "core/error.h"
#include "core/parallel.h"

namespace emaki::synth {

int plane_width(const Plane& p) {
  return std::visit([](const auto& v) { return v.width; }, p);
}
int plane_height(const Plane& p) {
  return std::visit([](const auto& v) { return v.height; }, p);
}
int plane_channels(const Plane& p) {
  return std::visit([](const auto& v) { return v.channels; }, p);
}

namespace {

// The band's rows' [min, max] per channel, NC channels (1 to 4) known at compile time so that
// the running values stay in registers.
template <int NC>
void band_ranges(const Plane& p, int y0, int y1, float* lo, float* hi) {
  const int w = plane_width(p);
  float l[NC], h[NC];
  for (int c = 0; c < NC; ++c) l[c] = INFINITY, h[c] = -INFINITY;
  for_each_row(p, y0, y1, [&](int, const float* row) {
    for (int x = 0; x < w; ++x, row += NC)
      for (int c = 0; c < NC; ++c) {
        l[c] = std::min(l[c], row[c]);
        h[c] = std::max(h[c], row[c]);
      }
  });
  for (int c = 0; c < NC; ++c) lo[c] = l[c], hi[c] = h[c];
}

}  // namespace

void plane_ranges(const Plane& p, std::vector<float>& lo, std::vector<float>& hi) {
  const int nc = plane_channels(p);
  CHECK(nc >= 1 && nc <= 4);
  CHECK_EQ(lo.size(), std::size_t(nc));
  CHECK_EQ(hi.size(), std::size_t(nc));
  std::mutex m;
  parallel_rows(plane_height(p), 32, [&](int y0, int y1) {
    float l[4], h[4];
    switch (nc) {
      case 1:
        band_ranges<1>(p, y0, y1, l, h);
        break;
      case 2:
        band_ranges<2>(p, y0, y1, l, h);
        break;
      case 3:
        band_ranges<3>(p, y0, y1, l, h);
        break;
      default:
        band_ranges<4>(p, y0, y1, l, h);
        break;
    }
    std::lock_guard lock(m);
    for (int c = 0; c < nc; ++c) {
      lo[std::size_t(c)] = std::min(lo[std::size_t(c)], l[c]);
      hi[std::size_t(c)] = std::max(hi[std::size_t(c)], h[c]);
    }
  });
}

void check_finite(const Plane& p, const std::string& name) {
  if (!is_float(p)) return;
  const auto& v = std::get<2>(p);
  // A value is not finite when its exponent bits are all set; or-ed over a row, branch-free.
  std::atomic<bool> bad{false};
  parallel_rows(v.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1 && !bad.load(std::memory_order_relaxed); ++y) {
      const float* row = v.row(y);
      uint32_t any = 0;
      for (int i = 0; i < v.width * v.channels; ++i) {
        uint32_t bits;
        std::memcpy(&bits, row + i, sizeof bits);
        any |= (bits & 0x7f800000u) == 0x7f800000u ? 1u : 0u;
      }
      if (any) bad.store(true, std::memory_order_relaxed);
    }
  });
  if (!bad) return;
  // Name the first bad pixel in row order, whichever band found one.
  for (int y = 0; y < v.height; ++y)
    for (int i = 0; i < v.width * v.channels; ++i)
      if (!std::isfinite(v.row(y)[i]))
        throw Error(name, fmt::format("non-finite value (NaN or Inf) at pixel ({}, {})",
                                      i / v.channels, y));
}

float guide_weight(const GuidePair& g, std::size_t count) {
  return g.weight < 0.0f ? 1.0f / float(count) : g.weight;
}

}  // namespace emaki::synth
