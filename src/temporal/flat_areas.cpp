#include "temporal/flat_areas.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/check.h"
#include "core/parallel.h"

namespace emaki::temporal {

namespace {

// 1 where every channel of every guide stays within `tol` over the pixel's patch, else 0.
Image<uint8_t> flat_pixels(const std::vector<ImageView<const float>>& guides,
                           ImageView<const float> mask, int r, float tol) {
  const int w = guides[0].width, h = guides[0].height;
  Image<uint8_t> flat(w, h, 1);
  parallel_rows(h, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        if (!mask.empty() && !(mask.at(x, y)[0] > 0.5f)) {
          flat(x, y) = 0;
          continue;
        }
        bool ok = true;
        for (const auto& g : guides) {
          for (int c = 0; c < g.channels && ok; ++c) {
            float lo = g.at(x, y)[c], hi = lo;
            for (int dy = -r; dy <= r; ++dy) {
              const int yy = std::clamp(y + dy, 0, h - 1);
              for (int dx = -r; dx <= r; ++dx) {
                const float v = g.at(std::clamp(x + dx, 0, w - 1), yy)[c];
                lo = std::min(lo, v), hi = std::max(hi, v);
              }
            }
            ok = hi - lo < tol;
          }
          if (!ok) break;
        }
        flat(x, y) = ok ? 1 : 0;
      }
  });
  return flat;
}

}  // namespace

Image<float> flat_areas(const std::vector<ImageView<const float>>& guides,
                        ImageView<const float> mask, const FlatAreaParams& p) {
  CHECK(!guides.empty());
  const int w = guides[0].width, h = guides[0].height;
  for (const auto& g : guides) CHECK(g.width == w && g.height == h);
  CHECK(mask.empty() || (mask.width == w && mask.height == h));
  const Image<uint8_t> flat = flat_pixels(guides, mask, p.patch_radius, p.tolerance);
  // Integral image of the flat pixels: exact integers, so the result is the same in any bands.
  const std::size_t stride = std::size_t(w) + 1;
  std::vector<int32_t> sum(stride * (h + 1), 0);
  for (int y = 0; y < h; ++y) {
    int32_t row = 0;
    for (int x = 0; x < w; ++x) {
      row += flat(x, y);
      sum[(y + 1) * stride + x + 1] = sum[y * stride + x + 1] + row;
    }
  }
  const int R = p.area_radius;
  const float span = std::max(1e-6f, p.share_full - p.share_none);
  Image<float> out(w, h, 1);
  parallel_rows(h, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const int ya = std::max(0, y - R), yb = std::min(h, y + R + 1);
      for (int x = 0; x < w; ++x) {
        if (!flat(x, y)) {
          out(x, y) = 0.0f;
          continue;
        }
        const int xa = std::max(0, x - R), xb = std::min(w, x + R + 1);
        const int32_t n = sum[yb * stride + xb] - sum[ya * stride + xb] - sum[yb * stride + xa] +
                          sum[ya * stride + xa];
        const float share = float(n) / float((xb - xa) * (yb - ya));  // the window in the image
        out(x, y) = std::clamp((share - p.share_none) / span, 0.0f, 1.0f);
      }
    }
  });
  return out;
}

}  // namespace emaki::temporal
