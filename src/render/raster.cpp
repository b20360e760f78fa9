#include "render/raster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "core/parallel.h"

namespace emaki::render {

void VisibilityBuffer::reset(int w, int h, bool with_attributes) {
  width = w;
  height = h;
  const std::size_t n = std::size_t(w) * h;
  key.assign(n, -std::numeric_limits<float>::infinity());
  tri.assign(n, -1);
  if (with_attributes) {
    b1.assign(n, 0.0f);
    b2.assign(n, 0.0f);
  } else {
    b1.clear();
    b2.clear();
  }
}

namespace {

constexpr int kSubBits = 8;  // vertex snapping: 1/256 sample
constexpr int kTile = 32;    // tile side in samples
// Guard band: geometry is clipped to |x|, |y| <= kGuard * w (NDC), which keeps snapped
// coordinates and edge products well inside int64.
constexpr float kGuard = 16.0f;

// A clipped, projected triangle ready for scan conversion.
struct ScreenTri {
  int64_t x[3], y[3];  // snapped sample coordinates (fixed point)
  float key[3];
  float inv_w[3];      // perspective weights
  glm::vec3 bary[3];   // barycentrics of each vertex in the original triangle
  int32_t source;      // original triangle index
  int x0, y0, x1, y1;  // sample bounding box, inclusive
};

struct PolyVertex {
  glm::vec4 c;  // x, y, w, depth
  glm::vec3 bary;
};

// Sutherland-Hodgman against one plane given by a signed-distance function.
template <typename F>
void clip_polygon(std::vector<PolyVertex>& poly, std::vector<PolyVertex>& scratch, F dist) {
  scratch.clear();
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const PolyVertex& a = poly[i];
    const PolyVertex& b = poly[(i + 1) % n];
    const float da = dist(a.c), db = dist(b.c);
    if (da >= 0) scratch.push_back(a);
    if ((da >= 0) != (db >= 0)) {
      // Interpolate from the lexicographically smaller end, so the two triangles sharing this
      // edge (which walk it in opposite directions) compute the very same point: no cracks.
      const bool a_first =
          std::tie(a.c.x, a.c.y, a.c.z, a.c.w) < std::tie(b.c.x, b.c.y, b.c.z, b.c.w);
      const PolyVertex& p = a_first ? a : b;
      const PolyVertex& q = a_first ? b : a;
      const float dp = a_first ? da : db, dq = a_first ? db : da;
      const float t = dp / (dp - dq);
      scratch.push_back({p.c + t * (q.c - p.c), p.bary + t * (q.bary - p.bary)});
    }
  }
  poly.swap(scratch);
}

// Trivial accept / reject against the near plane and the guard band: false drops the triangle;
// `inside` says it needs no clipping. A NaN or infinite coordinate (a degenerate camera, an
// overflowing transform) drops it: every comparison below would pass it through to the integer
// snapping.
bool accept(const ClipVertex* const v[3], float znear, bool& inside) {
  inside = true;
  int near_out = 0;
  bool finite = true;
  for (int k = 0; k < 3; ++k)
    finite = finite && std::isfinite(v[k]->x) && std::isfinite(v[k]->y) && std::isfinite(v[k]->w) &&
             std::isfinite(v[k]->depth);
  if (!finite) return false;
  for (int k = 0; k < 3; ++k) {
    if (v[k]->depth < znear) ++near_out;
    if (v[k]->depth < znear || std::abs(v[k]->x) > kGuard * v[k]->w ||
        std::abs(v[k]->y) > kGuard * v[k]->w)
      inside = false;
  }
  return near_out != 3;
}

void clip_to_guard_band(std::vector<PolyVertex>& poly, std::vector<PolyVertex>& scratch,
                        float znear) {
  clip_polygon(poly, scratch, [znear](const glm::vec4& c) { return c.w - znear; });
  clip_polygon(poly, scratch, [](const glm::vec4& c) { return kGuard * c.z - c.x; });
  clip_polygon(poly, scratch, [](const glm::vec4& c) { return kGuard * c.z + c.x; });
  clip_polygon(poly, scratch, [](const glm::vec4& c) { return kGuard * c.z - c.y; });
  clip_polygon(poly, scratch, [](const glm::vec4& c) { return kGuard * c.z + c.y; });
}

// A polygon vertex projected to snapped sample coordinates.
struct Projected {
  int64_t x, y;
  float key, inv_w;
  glm::vec3 bary;
};

// Projects every polygon vertex once (at most 9: a triangle clipped by 5 planes has 8) into
// pv[0..n). Clipped to the guard band, projected points lie within a few frame widths of the
// frame; one outside that (float error on huge inputs, a NaN from clipping between extreme
// points) drops the polygon (false) before it is snapped to integers and the edge products
// could overflow.
bool project(const std::vector<PolyVertex>& poly, bool perspective, int W, int H,
             Projected (&pv)[9], int& n) {
  const float sx = 0.5f * W, sy = 0.5f * H;
  const float sub = float(1 << kSubBits);
  n = std::min<int>(int(poly.size()), 9);
  const double limit = (double(kGuard) + 2.0) * double(std::max(W, H)) + 1.0;
  for (int k = 0; k < n; ++k) {
    const glm::vec4& c = poly[k].c;
    const float inv_w = 1.0f / c.z;
    const float px = (c.x * inv_w + 1.0f) * sx;
    const float py = (1.0f - c.y * inv_w) * sy;
    if (!(std::abs(double(px)) <= limit && std::abs(double(py)) <= limit) ||
        !std::isfinite(inv_w) || !std::isfinite(c.w))
      return false;
    pv[k] = {int64_t(std::llround(double(px) * sub)), int64_t(std::llround(double(py) * sub)),
             perspective ? 1.0f / c.w : -c.w, perspective ? inv_w : 1.0f, poly[k].bary};
  }
  return true;
}

// Fan-triangulates a projected polygon of source triangle `source`, keeping the triangles that
// cover a sample of the W x H grid.
void add_fan(const Projected (&pv)[9], int n, int32_t source, int W, int H,
             std::vector<ScreenTri>& tris) {
  for (int k = 1; k + 1 < n; ++k) {
    ScreenTri st;
    const Projected* q[3] = {&pv[0], &pv[k], &pv[k + 1]};
    const int64_t area =
        (q[1]->x - q[0]->x) * (q[2]->y - q[0]->y) - (q[1]->y - q[0]->y) * (q[2]->x - q[0]->x);
    if (area == 0) continue;
    if (area < 0) std::swap(q[1], q[2]);  // both faces are drawn; keep one winding
    int64_t minx = INT64_MAX, miny = INT64_MAX, maxx = INT64_MIN, maxy = INT64_MIN;
    for (int j = 0; j < 3; ++j) {
      st.x[j] = q[j]->x;
      st.y[j] = q[j]->y;
      st.key[j] = q[j]->key;
      st.inv_w[j] = q[j]->inv_w;
      st.bary[j] = q[j]->bary;
      minx = std::min(minx, q[j]->x), maxx = std::max(maxx, q[j]->x);
      miny = std::min(miny, q[j]->y), maxy = std::max(maxy, q[j]->y);
    }
    // Samples sit at (i + 0.5) sample units.
    const int64_t half = 1 << (kSubBits - 1);
    st.x0 = int(std::max<int64_t>(0, (minx - half + (1 << kSubBits) - 1) >> kSubBits));
    st.y0 = int(std::max<int64_t>(0, (miny - half + (1 << kSubBits) - 1) >> kSubBits));
    st.x1 = int(std::min<int64_t>(W - 1, (maxx - half) >> kSubBits));
    st.y1 = int(std::min<int64_t>(H - 1, (maxy - half) >> kSubBits));
    if (st.x0 > st.x1 || st.y0 > st.y1) continue;
    st.source = source;
    tris.push_back(st);
  }
}

// Clips and projects every triangle; serial, in triangle order, so the list (and
// tie-breaking) is fixed.
std::vector<ScreenTri> setup_triangles(const std::vector<ClipVertex>& vertices,
                                       const std::vector<uint32_t>& indices,
                                       const RasterOptions& options, int W, int H) {
  const std::size_t tri_count = indices.size() / 3;
  std::vector<ScreenTri> tris;
  tris.reserve(tri_count);
  std::vector<PolyVertex> poly, scratch;
  for (std::size_t t = 0; t < tri_count; ++t) {
    const ClipVertex* v[3] = {&vertices[indices[3 * t]], &vertices[indices[3 * t + 1]],
                              &vertices[indices[3 * t + 2]]};
    bool inside;
    if (!accept(v, options.znear, inside)) continue;
    poly.clear();
    for (int k = 0; k < 3; ++k) {
      glm::vec3 b(0.0f);
      b[k] = 1.0f;
      poly.push_back({glm::vec4(v[k]->x, v[k]->y, v[k]->w, v[k]->depth), b});
    }
    if (!inside) {
      clip_to_guard_band(poly, scratch, options.znear);
      if (poly.size() < 3) continue;
    }
    Projected pv[9];
    int n = 0;
    if (!project(poly, options.perspective, W, H, pv, n)) continue;
    add_fan(pv, n, int32_t(t), W, H, tris);
  }
  return tris;
}

// Draws the samples [x0, x1] x [y0, y1] of one triangle: exact integer edge functions, the
// nearest key wins (ties keep the triangle drawn first).
void draw_span(const ScreenTri& st, int x0, int y0, int x1, int y1, bool attrs,
               VisibilityBuffer& out) {
  // Edge e runs from vertex (e+1)%3 to (e+2)%3 and weighs vertex e.
  int64_t ex[3], ey[3], e_row[3], bias[3];
  const int64_t px0 = (int64_t(x0) << kSubBits) + (1 << (kSubBits - 1));
  const int64_t py0 = (int64_t(y0) << kSubBits) + (1 << (kSubBits - 1));
  for (int e = 0; e < 3; ++e) {
    const int a = (e + 1) % 3, c = (e + 2) % 3;
    const int64_t dx = st.x[c] - st.x[a], dy = st.y[c] - st.y[a];
    // Tie rule: a sample exactly on an edge belongs to the one of the two triangles
    // sharing it for which the edge runs "down" (or "left" when horizontal).
    bias[e] = (dy > 0 || (dy == 0 && dx < 0)) ? 0 : -1;
    ex[e] = -dy << kSubBits;  // change of the edge function per sample step in x
    ey[e] = dx << kSubBits;
    e_row[e] = dx * (py0 - st.y[a]) - dy * (px0 - st.x[a]);
  }
  const double inv_area = 1.0 / double((st.x[1] - st.x[0]) * (st.y[2] - st.y[0]) -
                                       (st.y[1] - st.y[0]) * (st.x[2] - st.x[0]));
  for (int y = y0; y <= y1; ++y) {
    int64_t e0 = e_row[0], e1 = e_row[1], e2 = e_row[2];
    for (int x = x0; x <= x1; ++x) {
      if ((e0 + bias[0]) >= 0 && (e1 + bias[1]) >= 0 && (e2 + bias[2]) >= 0) {
        const float l0 = float(double(e0) * inv_area), l1 = float(double(e1) * inv_area);
        const float l2 = 1.0f - l0 - l1;
        const float key = l0 * st.key[0] + l1 * st.key[1] + l2 * st.key[2];
        const std::size_t idx = out.index(x, y);
        if (key > out.key[idx]) {
          out.key[idx] = key;
          out.tri[idx] = st.source;
          if (attrs) {
            const float q0 = l0 * st.inv_w[0], q1 = l1 * st.inv_w[1], q2 = l2 * st.inv_w[2];
            const float s = 1.0f / (q0 + q1 + q2);
            const glm::vec3 bary =
                (q0 * s) * st.bary[0] + (q1 * s) * st.bary[1] + (q2 * s) * st.bary[2];
            out.b1[idx] = bary.y;
            out.b2[idx] = bary.z;
          }
        }
      }
      e0 += ex[0], e1 += ex[1], e2 += ex[2];
    }
    e_row[0] += ey[0], e_row[1] += ey[1], e_row[2] += ey[2];
  }
}

}  // namespace

void rasterize(const std::vector<ClipVertex>& vertices, const std::vector<uint32_t>& indices,
               const RasterOptions& options, VisibilityBuffer& out) {
  const int W = out.width, H = out.height;
  const std::vector<ScreenTri> tris = setup_triangles(vertices, indices, options, W, H);

  // Bin by tile, in passes of at most kMaxBinEntries entries: many large triangles would
  // otherwise need (triangles x tiles they cover) entries at once (gigabytes for a file of a
  // million frame-filling triangles). Passes run in triangle order, so the result is the same.
  constexpr std::size_t kMaxBinEntries = std::size_t(1) << 24;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  std::vector<std::vector<int32_t>> bins(std::size_t(tiles_x) * tiles_y);
  const bool attrs = options.with_attributes;
  for (std::size_t first = 0, end = 0; first < tris.size(); first = end) {
    for (auto& bin : bins) bin.clear();
    std::size_t entries = 0;
    for (end = first; end < tris.size(); ++end) {
      const ScreenTri& st = tris[end];
      const std::size_t n = std::size_t(st.y1 / kTile - st.y0 / kTile + 1) *
                            std::size_t(st.x1 / kTile - st.x0 / kTile + 1);
      if (end > first && entries + n > kMaxBinEntries) break;
      entries += n;
      for (int ty = st.y0 / kTile; ty <= st.y1 / kTile; ++ty)
        for (int tx = st.x0 / kTile; tx <= st.x1 / kTile; ++tx)
          bins[ty * tiles_x + tx].push_back(int32_t(end));
    }
    parallel_for(int64_t(bins.size()), 1, [&](int64_t b0, int64_t b1) {
      for (int64_t b = b0; b < b1; ++b) {
        const int tx = int(b % tiles_x), ty = int(b / tiles_x);
        const int tx0 = tx * kTile, ty0 = ty * kTile;
        const int tx1 = std::min(W, tx0 + kTile) - 1, ty1 = std::min(H, ty0 + kTile) - 1;
        for (int32_t i : bins[b]) {
          const ScreenTri& st = tris[i];
          const int x0 = std::max(st.x0, tx0), x1 = std::min(st.x1, tx1);
          const int y0 = std::max(st.y0, ty0), y1 = std::min(st.y1, ty1);
          if (x0 <= x1 && y0 <= y1) draw_span(st, x0, y0, x1, y1, attrs, out);
        }
      }
    });
  }
}

}  // namespace emaki::render
