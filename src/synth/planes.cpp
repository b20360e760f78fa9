// Planes: their sizes, value ranges and finiteness.
#include "synth/planes.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>

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

void plane_range(const Plane& p, int c, float& lo, float& hi) {
  std::mutex m;
  const float lo0 = lo, hi0 = hi;
  parallel_rows(plane_height(p), 32, [&](int y0, int y1) {
    float l = lo0, h = hi0;
    const int nc = plane_channels(p), w = plane_width(p);
    for_each_row(p, y0, y1, [&](int, const float* row) {
      for (int x = 0; x < w; ++x) {
        l = std::min(l, row[x * nc + c]);
        h = std::max(h, row[x * nc + c]);
      }
    });
    std::lock_guard lock(m);
    lo = std::min(lo, l);
    hi = std::max(hi, h);
  });
}

void check_finite(const Plane& p, const std::string& name) {
  if (!is_float(p)) return;
  const auto& v = std::get<2>(p);
  std::atomic<bool> bad{false};
  parallel_rows(v.height, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1 && !bad.load(std::memory_order_relaxed); ++y)
      for (int i = 0; i < v.width * v.channels; ++i)
        if (!std::isfinite(v.row(y)[i])) bad.store(true, std::memory_order_relaxed);
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
