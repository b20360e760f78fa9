#include "temporal/coherent_field.h"

#include <cstring>
#include <vector>

#include "core/parallel.h"

namespace emaki::temporal {
namespace {

struct Offset {
  int32_t dx = 0, dy = 0;
  int count = 0;
};

// The offset pixel (x, y) takes: see coherent_field().
Offset snapped_offset(ImageView<const int32_t> f, int x, int y, int r, std::vector<Offset>& seen) {
  seen.clear();
  const Offset own{f(x, y, 0) - x, f(x, y, 1) - y, 0};
  for (int yy = std::max(0, y - r); yy <= std::min(f.height - 1, y + r); ++yy)
    for (int xx = std::max(0, x - r); xx <= std::min(f.width - 1, x + r); ++xx) {
      if (f(xx, yy, 0) < 0) continue;
      const int32_t dx = f(xx, yy, 0) - xx, dy = f(xx, yy, 1) - yy;
      Offset* o = nullptr;
      for (Offset& s : seen)
        if (s.dx == dx && s.dy == dy) o = &s;
      if (!o) o = &seen.emplace_back(Offset{dx, dy, 0});
      ++o->count;
    }
  Offset best = own;
  for (const Offset& s : seen)
    if (s.dx == own.dx && s.dy == own.dy) best.count = s.count;
  for (const Offset& s : seen)
    if (s.count > best.count) best = s;
  return best;
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
        const Offset o = snapped_offset(field, x, y, radius, seen);
        out(x, y, 0) = x + o.dx;
        out(x, y, 1) = y + o.dy;
      }
  });
  return out;
}

}  // namespace emaki::temporal
