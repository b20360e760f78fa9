#include "temporal/confidence.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/check.h"
#include "core/parallel.h"
#include "synth/voting.h"

namespace emaki::temporal {

namespace {

float rest_distance(const float* a, const float* b) {
  const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// The largest rest-position step from (x, y) to a 4-neighbour showing the same object at t: how
// much rest space one pixel spans there.
float footprint(ImageView<const float> cur, int x, int y) {
  const float* p = cur.at(x, y);
  float f = 0.0f;
  const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  for (int k = 0; k < 4; ++k) {
    const int nx = x + dx[k], ny = y + dy[k];
    if (nx < 0 || ny < 0 || nx >= cur.width || ny >= cur.height) continue;
    const float* q = cur.at(nx, ny);
    if (q[3] == p[3]) f = std::max(f, rest_distance(p, q));
  }
  return f;
}

}  // namespace

Image<uint8_t> visible_before(const Surfaces& s, float tolerance) {
  const ImageView<const float> prev = s.previous, cur = s.current, motion = s.motion;
  CHECK_EQ(prev.width, cur.width);
  CHECK_EQ(prev.height, cur.height);
  CHECK_EQ(motion.width, cur.width);
  CHECK_GE(cur.channels, 4);
  const int w = cur.width, h = cur.height;
  Image<uint8_t> out(w, h, 1);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const float* p = cur.at(x, y);
        const float sx = x + motion(x, y, 0), sy = y + motion(x, y, 1);
        const int x0 = int(std::floor(sx)), y0s = int(std::floor(sy));
        // The pixels the bilinear sample at (sx, sy) reads: one to four.
        const int ni = sx > float(x0) ? 2 : 1, nj = sy > float(y0s) ? 2 : 1;
        // A pixel with no neighbour of its object has no footprint: a tiny one keeps exact
        // matches.
        const float tol = tolerance * std::max(footprint(cur, x, y), 1e-6f);
        bool seen = false;
        for (int j = 0; j < nj && !seen; ++j)
          for (int i = 0; i < ni && !seen; ++i) {
            const int qx = x0 + i, qy = y0s + j;
            if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const float* q = prev.at(qx, qy);
            seen = q[3] == p[3] && rest_distance(p, q) <= tol;
          }
        out(x, y) = seen ? 1 : 0;
      }
  });
  return out;
}

namespace {

// Where an object id shows in a frame: its pixels' bounding box, inclusive.
struct IdBox {
  float id;
  int x0, y0, x1, y1;
};

// The share of the pixels within `radius` of each pixel (clamped window) that show `b.id`: the
// mean of per-row shares over the window's rows, in order from the top. Computed only where a
// pixel of the id is within reach (its box grown by `radius`): elsewhere every row share is 0,
// and so is the result, as the calloc'd image holds it. Skipping those rows' zeros in a sum of
// non-negative values changes no bit.
Image<float> box_share(ImageView<const float> ids, const IdBox& b, int radius) {
  const int w = ids.width, h = ids.height;
  const int x0 = std::max(0, b.x0 - radius), x1 = std::min(w - 1, b.x1 + radius);
  const int y0 = std::max(0, b.y0 - radius), y1 = std::min(h - 1, b.y1 + radius);
  Image<float> rows(w, h, 1), out(w, h, 1);
  // Rows: the hits within the window, counted by sliding it along the row (integers: exact).
  parallel_rows(b.y1 - b.y0 + 1, 32, [&](int r0, int r1) {
    for (int y = b.y0 + r0; y < b.y0 + r1; ++y) {
      const float* src = ids.row(y);
      float* dst = rows.row(y);
      auto hit = [&](int u) { return src[std::size_t(u) * std::size_t(ids.channels) + 3] == b.id; };
      int count = 0;
      // The window of x0 - 1, which the first step below slides to x0's.
      for (int u = std::max(0, x0 - radius - 1); u <= std::min(w - 1, x0 + radius - 1); ++u)
        count += hit(u);
      for (int x = x0; x <= x1; ++x) {
        if (x + radius < w) count += hit(x + radius);
        if (x - radius - 1 >= 0) count -= hit(x - radius - 1);
        const int n = std::min(w - 1, x + radius) - std::max(0, x - radius) + 1;
        dst[x] = float(count) / float(n);
      }
    }
  });
  // Columns: each pixel's sum over the window's rows from the top, a row at a time.
  parallel_rows(y1 - y0 + 1, 32, [&](int r0, int r1) {
    std::vector<float> sum(std::size_t(x1 - x0 + 1));
    for (int y = y0 + r0; y < y0 + r1; ++y) {
      std::fill(sum.begin(), sum.end(), 0.0f);
      for (int v = std::max({0, y - radius, b.y0}); v <= std::min({h - 1, y + radius, b.y1}); ++v) {
        const float* src = rows.row(v) + x0;
        for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += src[i];
      }
      const float n = float(std::min(h - 1, y + radius) - std::max(0, y - radius) + 1);
      float* dst = out.row(y) + x0;
      for (std::size_t i = 0; i < sum.size(); ++i) dst[i] = sum[i] / n;
    }
  });
  return out;
}

}  // namespace

IdShares id_shares(ImageView<const float> ids, int radius) {
  IdShares s;
  s.radius = radius;
  // The ids of each band of rows in first-seen order with their boxes, then merged in band
  // order: the order of a scan of the whole image row by row.
  const int band = 32, bands = (ids.height + band - 1) / band;
  std::vector<std::vector<IdBox>> seen(std::size_t(std::max(bands, 0)));
  parallel_for(bands, 1, [&](int64_t b0, int64_t b1) {
    for (int64_t b = b0; b < b1; ++b) {
      std::vector<IdBox>& v = seen[std::size_t(b)];
      for (int y = int(b) * band; y < std::min(ids.height, int(b + 1) * band); ++y)
        for (int x = 0; x < ids.width; ++x) {
          const float k = ids(x, y, 3);
          auto it = std::find_if(v.begin(), v.end(), [k](const IdBox& e) { return e.id == k; });
          if (it == v.end()) {
            v.push_back({k, x, y, x, y});
          } else {
            it->x0 = std::min(it->x0, x), it->x1 = std::max(it->x1, x);
            it->y1 = y;
          }
        }
    }
  });
  std::vector<IdBox> boxes;
  for (const std::vector<IdBox>& v : seen)
    for (const IdBox& e : v) {
      auto it =
          std::find_if(boxes.begin(), boxes.end(), [&](const IdBox& o) { return o.id == e.id; });
      if (it == boxes.end()) {
        boxes.push_back(e);
      } else {
        it->x0 = std::min(it->x0, e.x0), it->x1 = std::max(it->x1, e.x1);
        it->y0 = std::min(it->y0, e.y0), it->y1 = std::max(it->y1, e.y1);
      }
    }
  for (const IdBox& b : boxes) {
    s.ids.push_back(b.id);
    s.share.push_back(box_share(ids, b, radius));
  }
  return s;
}

Image<float> foreign_share(const Image<int32_t>& nnf, const Surfaces& s, int patch_size,
                           int footprint) {
  return foreign_share(nnf, {}, s, patch_size, id_shares(s.previous, footprint));
}

Image<float> foreign_share(const Image<int32_t>& nnf, const Image<uint8_t>& active,
                           const Surfaces& s, int patch_size, const IdShares& shares) {
  const ImageView<const float> prev = s.previous, cur = s.current;
  const int w = nnf.width(), h = nnf.height(), r = patch_size / 2;
  CHECK_EQ(cur.width, w);
  CHECK_EQ(cur.height, h);
  CHECK(!shares.empty());
  const bool all = active.empty();
  CHECK(all || (active.width() == w && active.height() == h));
  Image<float> out(w, h, 1);
  // A pixel whose window holds no active patch centre has no vote: 0, without looking.
  const Image<uint8_t> voted = all ? Image<uint8_t>() : synth::dilate_mask(active, r);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        if (!all && !voted(x, y)) continue;
        const int ux0 = std::max(0, x - r), ux1 = std::min(w - 1, x + r);
        const int uy0 = std::max(0, y - r), uy1 = std::min(h - 1, y + r);
        // The pixel's own object, looked up once for its votes.
        const Image<float>* own = shares.find(cur(x, y, 3));
        int votes = 0;
        float foreign = 0.0f;
        for (int uy = uy0; uy <= uy1; ++uy)
          for (int ux = ux0; ux <= ux1; ++ux) {
            if (!all && !active(ux, uy)) continue;
            const int32_t* m = nnf.at(ux, uy);
            if (m[0] < 0) continue;
            const int qx = m[0] + (x - ux), qy = m[1] + (y - uy);
            if (qx < 0 || qy < 0 || qx >= prev.width || qy >= prev.height) continue;
            ++votes;
            foreign += 1.0f - (own ? (*own)(qx, qy) : 0.0f);
          }
        out(x, y) = votes ? foreign / float(votes) : 0.0f;
      }
  });
  return out;
}

Image<float> confidence(const Image<uint8_t>& visible, const Image<float>& foreign,
                        const Image<float>& error, int patch_size, const ConfidenceParams& cp,
                        const Image<float>& change) {
  const int w = visible.width(), h = visible.height();
  const bool changes = !change.empty() && cp.change_none > 0.0f;
  CHECK(!changes || cp.change_full < cp.change_none);
  CHECK_EQ(foreign.width(), w);
  CHECK_EQ(error.width(), w);
  CHECK_LT(cp.error_full, cp.error_none);
  const double norm = 1.0 / (65025.0 * patch_size * patch_size);
  Image<float> c(w, h, 1);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const float rms = float(std::sqrt(std::max(0.0, double(error(x, y)) * norm)));
        const float ramp =
            std::clamp((cp.error_none - rms) / (cp.error_none - cp.error_full), 0.0f, 1.0f);
        const float own = std::clamp(1.0f - foreign(x, y) / cp.foreign_none, 0.0f, 1.0f);
        const float same =
            changes
                ? std::clamp((cp.change_none - change(x, y)) / (cp.change_none - cp.change_full),
                             0.0f, 1.0f)
                : 1.0f;
        c(x, y) = visible(x, y) ? own * ramp * same : 0.0f;
      }
  });
  if (cp.erode <= 0) return c;
  // Min filter, separable: rows then columns.
  Image<float> rows(w, h, 1), out(w, h, 1);
  const int e = cp.erode;
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        float m = 1.0f;
        for (int k = std::max(0, x - e); k <= std::min(w - 1, x + e); ++k) m = std::min(m, c(k, y));
        rows(x, y) = m;
      }
  });
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        float m = 1.0f;
        for (int k = std::max(0, y - e); k <= std::min(h - 1, y + e); ++k)
          m = std::min(m, rows(x, k));
        out(x, y) = m;
      }
  });
  return out;
}

}  // namespace emaki::temporal
