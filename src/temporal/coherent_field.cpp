#include "temporal/coherent_field.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "core/parallel.h"

namespace emaki::temporal {
namespace {

// An offset (patch centre minus position) as one key, and how many pixels of a window have it.
struct Offset {
  int64_t key = 0;
  int count = 0;
};

int64_t offset_key(ImageView<const int32_t> f, int x, int y) {
  return int64_t(uint64_t(uint32_t(f(x, y, 0) - x)) << 32 | uint32_t(f(x, y, 1) - y));
}

// The offset pixel (x, y) takes: see coherent_field().
int64_t snapped_offset(ImageView<const int32_t> f, int x, int y, int r, std::vector<Offset>& seen) {
  const int64_t own = offset_key(f, x, y);
  const int x0 = std::max(0, x - r), x1 = std::min(f.width - 1, x + r);
  const int y0 = std::max(0, y - r), y1 = std::min(f.height - 1, y + r);
  // First the pixels that share the own offset: when they are at least half of the window's
  // pixels with a patch, no other offset can have more of them.
  int own_count = 0, valid = 0;
  for (int yy = y0; yy <= y1; ++yy)
    for (int xx = x0; xx <= x1; ++xx)
      if (f(xx, yy, 0) >= 0) {
        ++valid;
        own_count += offset_key(f, xx, yy) == own;
      }
  if (2 * own_count >= valid) return own;
  seen.clear();
  for (int yy = y0; yy <= y1; ++yy)
    for (int xx = x0; xx <= x1; ++xx) {
      if (f(xx, yy, 0) < 0) continue;
      const int64_t k = offset_key(f, xx, yy);
      Offset* o = nullptr;
      for (Offset& s : seen)
        if (s.key == k) o = &s;
      if (!o) o = &seen.emplace_back(Offset{k, 0});
      ++o->count;
    }
  Offset best{own, own_count};
  for (const Offset& s : seen)
    if (s.count > best.count) best = s;
  return best.key;
}

}  // namespace

Image<int32_t> coherent_field(ImageView<const int32_t> field, int radius) {
  Image<int32_t> out(field.width, field.height, 2);
  for (int y = 0; y < field.height; ++y)
    std::memcpy(out.row(y), field.row(y), sizeof(int32_t) * 2 * std::size_t(field.width));
  if (radius <= 0) return out;
  parallel_rows(field.height, 16, [&](int y0, int y1) {
    std::vector<Offset> seen;
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < field.width; ++x) {
        if (field(x, y, 0) < 0) continue;
        const int64_t o = snapped_offset(field, x, y, radius, seen);
        out(x, y, 0) = x + int32_t(uint32_t(uint64_t(o) >> 32));
        out(x, y, 1) = y + int32_t(uint32_t(uint64_t(o)));
      }
  });
  return out;
}

}  // namespace emaki::temporal
