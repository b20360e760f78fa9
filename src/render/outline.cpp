#include "render/outline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/parallel.h"
#include "render/passes.h"

namespace emaki::render::detail {

namespace {

struct OutlineTri {
  int object_id, material_id;
  glm::vec3 view_normal;  // plane of the triangle in view space: dot(n, p) = d
  float view_d;
  glm::vec3 face_normal;
};

// What separates two neighbouring samples: their triangles' ids, planes and normals.
class EdgeFinder {
 public:
  EdgeFinder(const VisibilityBuffer& vb, const FrameGeometry& g, const Projector& proj,
             const RenderOptions& opt)
      : vb_(vb), proj_(proj), aa_(opt.aa), tris_(g.tris.size()) {
    const glm::mat3 rot(proj.cam.view);
    for (std::size_t t = 0; t < g.tris.size(); ++t) {
      const glm::vec3 p0 = glm::vec3(proj.cam.view * glm::vec4(g.pos[g.indices[3 * t]], 1.0f));
      const glm::vec3 n = rot * g.tris[t].face_normal;
      tris_[t] = {g.tris[t].object_id, g.tris[t].material_id, n, glm::dot(n, p0),
                  g.tris[t].face_normal};
    }
    cos_crease_ =
        std::cos(std::clamp(opt.crease_deg, 0.0f, 180.0f) * std::numbers::pi_v<float> / 180.0f);
    jump_ = opt.depth_jump;
  }

  // 0: no line between the two samples, 1: silhouette / depth jump / id boundary, 2: crease.
  uint8_t edge(int ax, int ay, int bx, int by) const {
    const std::size_t ia = vb_.index(ax, ay), ib = vb_.index(bx, by);
    const int32_t a = vb_.tri[ia], b = vb_.tri[ib];
    if (a == b) return 0;
    const int oa = a < 0 ? 0 : tris_[a].object_id, ob = b < 0 ? 0 : tris_[b].object_id;
    // The ground's far edge against the background is not a line anyone wants.
    if ((oa == 0 && ob == kGroundObject) || (ob == 0 && oa == kGroundObject)) return 0;
    if (a < 0 || b < 0) return 1;
    if (oa != ob || tris_[a].material_id != tris_[b].material_id) return 1;
    const float da = proj_.depth_from_key(vb_.key[ia]), db = proj_.depth_from_key(vb_.key[ib]);
    const float err =
        std::min(plane_error(tris_[a], bx, by, db), plane_error(tris_[b], ax, ay, da));
    if (err > jump_) return 1;
    return glm::dot(tris_[a].face_normal, tris_[b].face_normal) < cos_crease_ ? 2 : 0;
  }

 private:
  // Relative error of predicting sample b's depth from the plane of sample a's triangle.
  float plane_error(const OutlineTri& ta, int bx, int by, float depth_b) const {
    glm::vec3 o, d;
    proj_.ray((bx + 0.5f) / aa_, (by + 0.5f) / aa_, o, d);
    const float denom = glm::dot(ta.view_normal, d);
    if (std::abs(denom) < 1e-12f) return std::numeric_limits<float>::infinity();
    const float t = (ta.view_d - glm::dot(ta.view_normal, o)) / denom;
    return std::abs(t - depth_b) / std::max(depth_b, 1e-12f);
  }

  const VisibilityBuffer& vb_;
  const Projector& proj_;
  const int aa_;  // samples per pixel side
  std::vector<OutlineTri> tris_;
  float cos_crease_ = 1.0f, jump_ = 0.0f;
};

// Each sample's edges to the right (bits 0-1) and below (bits 2-3).
std::vector<uint8_t> edge_bits(const VisibilityBuffer& vb, const EdgeFinder& edges) {
  const int W = vb.width, H = vb.height;
  std::vector<uint8_t> bits(std::size_t(W) * H, 0);
  parallel_rows(H, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        uint8_t b = 0;
        if (x + 1 < W) b |= edges.edge(x, y, x + 1, y);
        if (y + 1 < H) b |= edges.edge(x, y, x, y + 1) << 2;
        bits[vb.index(x, y)] = b;
      }
  });
  return bits;
}

// 1 on a silhouette / id line, 2 on a crease only. A sample is on a line when it differs from
// any of its four neighbours (both sides are marked, so lines centre on the boundary).
std::vector<uint8_t> line_marks(const VisibilityBuffer& vb, const std::vector<uint8_t>& bits) {
  const int W = vb.width, H = vb.height;
  std::vector<uint8_t> mark(std::size_t(W) * H, 0);
  parallel_rows(H, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = vb.index(x, y);
        const uint8_t b = (bits[i] & 3) | (bits[i] >> 2) | (x > 0 ? bits[i - 1] & 3 : 0) |
                          (y > 0 ? bits[i - W] >> 2 : 0);
        mark[i] = (b & 1) ? 1 : (b & 2) ? 2 : 0;
      }
  });
  return mark;
}

// A crease mark with almost no marked samples around it is where a few faces meet at a
// vertex, not a crease line: it would print as a speck, so it is dropped.
std::vector<uint8_t> drop_crease_specks(const VisibilityBuffer& vb,
                                        const std::vector<uint8_t>& mark) {
  const int W = vb.width, H = vb.height;
  std::vector<uint8_t> keep(std::size_t(W) * H, 0);
  parallel_rows(H, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = vb.index(x, y);
        if (mark[i] != 2) {
          keep[i] = mark[i];
          continue;
        }
        int around = 0;
        for (int dy = -3; dy <= 3; ++dy)
          for (int dx = -3; dx <= 3; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < W && yy < H && mark[vb.index(xx, yy)]) ++around;
          }
        keep[i] = around >= 8 ? 2 : 0;
      }
  });
  return keep;
}

// Horizontal distance to the nearest marked sample in the row, capped at `far`.
std::vector<float> row_distances(const VisibilityBuffer& vb, const std::vector<uint8_t>& keep,
                                 float far) {
  const int W = vb.width, H = vb.height;
  std::vector<float> hdist(std::size_t(W) * H, far);
  parallel_rows(H, 16, [&](int y0, int y1) {
    std::vector<uint8_t> marked(W);
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < W; ++x) marked[x] = keep[vb.index(x, y)] != 0;
      float* row = hdist.data() + std::size_t(y) * W;
      float d = far;
      for (int x = 0; x < W; ++x) row[x] = d = marked[x] ? 0.0f : std::min(far, d + 1.0f);
      d = far;
      for (int x = W - 1; x >= 0; --x)
        row[x] = std::min(row[x], d = marked[x] ? 0.0f : std::min(far, d + 1.0f));
    }
  });
  return hdist;
}

// Which (sample row, pixel column) spans hold any sample near a line: most pixels have none in
// their vertical window and are skipped.
std::vector<uint8_t> near_lines(const std::vector<float>& hdist, int W, int H, int S, int Wp,
                                float far) {
  std::vector<uint8_t> near(std::size_t(H) * Wp, 0);
  parallel_rows(H, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int px = 0; px < Wp; ++px)
        for (int sx = px * S; sx < (px + 1) * S; ++sx)
          if (hdist[std::size_t(y) * W + sx] < far) near[std::size_t(y) * Wp + px] = 1;
  });
  return near;
}

}  // namespace

void draw_outline(const VisibilityBuffer& vb, const FrameGeometry& g, const Projector& proj,
                  const RenderOptions& opt, Image<float>& frame) {
  if (opt.outline_width <= 0.0f) return;
  const int S = opt.aa;
  const int W = vb.width, H = vb.height;
  const EdgeFinder edges(vb, g, proj, opt);
  const std::vector<uint8_t> keep = drop_crease_specks(vb, line_marks(vb, edge_bits(vb, edges)));
  const float half_width = 0.5f * opt.outline_width * S;  // in samples
  const int reach = int(std::ceil(half_width)) + 1;
  const float far = float(reach + 1);
  const std::vector<float> hdist = row_distances(vb, keep, far);
  const int Wp = frame.width(), Hp = frame.height();
  const std::vector<uint8_t> near = near_lines(hdist, W, H, S, Wp, far);
  // Vertical combination gives the exact Euclidean distance within `reach`; a sample's coverage
  // is how much of it a line of the given width centred on the boundary covers.
  parallel_rows(Hp, 8, [&](int py0, int py1) {
    for (int py = py0; py < py1; ++py)
      for (int px = 0; px < Wp; ++px) {
        bool any = false;
        for (int yy = std::max(0, py * S - reach); yy < std::min(H, (py + 1) * S + reach); ++yy)
          any = any || near[std::size_t(yy) * Wp + px];
        if (!any) continue;
        float sum = 0.0f;
        for (int sy = py * S; sy < (py + 1) * S; ++sy)
          for (int sx = px * S; sx < (px + 1) * S; ++sx) {
            float best = far * far;
            for (int dy = -reach; dy <= reach; ++dy) {
              const int yy = sy + dy;
              if (yy < 0 || yy >= H) continue;
              const float h = hdist[std::size_t(yy) * W + sx];
              best = std::min(best, h * h + float(dy * dy));
            }
            sum += std::clamp(half_width - std::sqrt(best), 0.0f, 1.0f);
          }
        frame(px, py, kOutline) = sum / float(S * S);
      }
  });
}

}  // namespace emaki::render::detail
