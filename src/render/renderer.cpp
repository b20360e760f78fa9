#include "render/renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <numbers>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "render/raster.h"

namespace emaki::render {

using scene::Bounds;
using scene::ViewCamera;

namespace {

constexpr int kGroundObject = 1;
constexpr int kGroundMaterial = 1;
constexpr int kFirstSceneId = 2;
// 8K at 3x3 samples per pixel; more would need gigabytes more of sample buffers.
constexpr double kMaxSamples = 7680.0 * 4320.0 * 9.0;
// Frames whose poses bound the shot (see the ShotRenderer constructor).
constexpr int64_t kMaxBoundsFrames = 4096;

Bounds cube_around(const Bounds& b) {
  if (b.empty()) return {glm::vec3(-1.0f), glm::vec3(1.0f)};
  const float side = std::max({b.size().x, b.size().y, b.size().z, 1e-6f});
  return {b.center() - 0.5f * side, b.center() + 0.5f * side};
}

glm::vec3 normalise_in(const Bounds& cube, const glm::vec3& p) {
  return (p - cube.lo) / (cube.hi.x - cube.lo.x);
}

// ---------------------------------------------------------------------------------------------
// Projection

struct Projector {
  ViewCamera cam;
  float aspect = 1.0f;
  int width = 1, height = 1;  // output pixels

  ClipVertex clip(const glm::vec3& p) const {
    const glm::vec3 c = glm::vec3(cam.view * glm::vec4(p, 1.0f));
    const float depth = -c.z;
    if (cam.perspective)
      return {c.x / (cam.tan_half_fov * aspect) + cam.shift.x * depth,
              c.y / cam.tan_half_fov + cam.shift.y * depth, depth, depth};
    return {c.x / (cam.ortho_half_height * aspect) + cam.shift.x,
            c.y / cam.ortho_half_height + cam.shift.y, 1.0f, depth};
  }
  // Pixel coordinates (x right, y down, pixel centres at +0.5).
  glm::vec2 pixel(const glm::vec3& p) const {
    const ClipVertex v = clip(p);
    const float w = std::abs(v.w) > 1e-20f ? v.w : 1e-20f;
    return {(v.x / w + 1.0f) * 0.5f * width, (1.0f - v.y / w) * 0.5f * height};
  }
  // The view-space ray through a point of the image (pixel coordinates).
  void ray(float px, float py, glm::vec3& origin, glm::vec3& dir) const {
    const float nx = px / width * 2.0f - 1.0f - cam.shift.x;
    const float ny = 1.0f - py / height * 2.0f - cam.shift.y;
    if (cam.perspective) {
      origin = glm::vec3(0.0f);
      dir = glm::vec3(nx * cam.tan_half_fov * aspect, ny * cam.tan_half_fov, -1.0f);
    } else {
      origin = glm::vec3(nx * cam.ortho_half_height * aspect, ny * cam.ortho_half_height, 0.0f);
      dir = glm::vec3(0.0f, 0.0f, -1.0f);
    }
  }
  float depth_from_key(float key) const { return cam.perspective ? 1.0f / key : -key; }
};

// ---------------------------------------------------------------------------------------------
// Per-frame geometry: every drawn triangle with its vertices at this frame and the previous one

struct TriInfo {
  int object_id;
  int material_id;
  const scene::Material* material;  // nullptr: default white (or ground)
  glm::vec3 face_normal;            // world, unit
};

struct FrameGeometry {
  std::vector<glm::vec3> pos, prev_pos, normal, rest;
  std::vector<glm::vec2> uv;
  std::vector<uint32_t> indices;
  std::vector<TriInfo> tris;
  std::size_t caster_indices = 0;  // indices before the ground's
  glm::vec3 ground_color{0.8f};
};

FrameGeometry build_geometry(const scene::Scene& scene, const scene::PosedScene& cur,
                             const scene::PosedScene& prev, const Bounds& position_box,
                             const Bounds& rest_box, const scene::GroundSpec& ground,
                             float ground_height, const Bounds& shot_bounds) {
  FrameGeometry g;
  const int default_material = kFirstSceneId + int(scene.materials.size());
  for (std::size_t p = 0; p < cur.primitives.size(); ++p) {
    const scene::PosedPrimitive& a = cur.primitives[p];
    const scene::PosedPrimitive& b = prev.primitives[p];
    const uint32_t base = uint32_t(g.pos.size());
    const std::size_t nv = a.world_positions.size();
    const bool has_uv = a.uvs && a.uvs->size() == nv;
    for (std::size_t v = 0; v < nv; ++v) {
      g.pos.push_back(a.world_positions[v]);
      g.prev_pos.push_back(b.world_positions[v]);
      g.normal.push_back(a.world_normals[v]);
      g.rest.push_back(normalise_in(rest_box, (*a.rest_positions)[v]));
      g.uv.push_back(has_uv ? (*a.uvs)[v] : glm::vec2(0.0f));
    }
    const scene::Material* mat = a.material >= 0 ? &scene.materials[a.material] : nullptr;
    const int material_id = a.material >= 0 ? kFirstSceneId + a.material : default_material;
    const std::vector<uint32_t>& idx = *a.indices;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
      const uint32_t i0 = base + idx[t], i1 = base + idx[t + 1], i2 = base + idx[t + 2];
      g.indices.insert(g.indices.end(), {i0, i1, i2});
      glm::vec3 fn = glm::cross(g.pos[i1] - g.pos[i0], g.pos[i2] - g.pos[i0]);
      const float len = glm::length(fn);
      fn = len > 0.0f ? fn / len : glm::vec3(0, 1, 0);
      g.tris.push_back({kFirstSceneId + a.object_id, material_id, mat, fn});
    }
  }
  g.caster_indices = g.indices.size();
  if (ground.enabled) {
    const glm::vec3 c = shot_bounds.empty() ? glm::vec3(0.0f) : shot_bounds.center();
    const float extent =
        shot_bounds.empty() ? 1.0f : std::max(shot_bounds.size().x, shot_bounds.size().z);
    const float half = 0.5f * (ground.size > 0.0f ? ground.size : 6.0f * std::max(extent, 1e-3f));
    const uint32_t base = uint32_t(g.pos.size());
    const glm::vec3 corners[4] = {{c.x - half, ground_height, c.z - half},
                                  {c.x + half, ground_height, c.z - half},
                                  {c.x + half, ground_height, c.z + half},
                                  {c.x - half, ground_height, c.z + half}};
    for (const glm::vec3& q : corners) {
      g.pos.push_back(q);
      g.prev_pos.push_back(q);
      g.normal.push_back({0, 1, 0});
      // The ground is static: its rest position is its place in the shot's box.
      g.rest.push_back(normalise_in(position_box, q));
      g.uv.push_back(glm::vec2(0.0f));
    }
    g.indices.insert(g.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    g.tris.push_back({kGroundObject, kGroundMaterial, nullptr, {0, 1, 0}});
    g.tris.push_back({kGroundObject, kGroundMaterial, nullptr, {0, 1, 0}});
    g.ground_color = ground.color;
  }
  return g;
}

// ---------------------------------------------------------------------------------------------
// Texture lookup

float wrap_coord(float u, scene::Texture::Wrap mode) {
  switch (mode) {
    case scene::Texture::Wrap::kClamp:
      return std::clamp(u, 0.0f, 1.0f);
    case scene::Texture::Wrap::kMirror: {
      const float f = u - 2.0f * std::floor(0.5f * u);
      return f > 1.0f ? 2.0f - f : f;
    }
    default:
      return u - std::floor(u);
  }
}

glm::vec4 sample_texture(const scene::Texture& t, glm::vec2 uv) {
  const int w = t.rgba.width(), h = t.rgba.height();
  // A non-finite uv (from a degenerate triangle's barycentrics) reads texel 0: converting it to
  // int would be undefined.
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  const float x = wrap_coord(uv.x, t.wrap_s) * w - 0.5f;
  const float y = wrap_coord(uv.y, t.wrap_t) * h - 0.5f;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - x0, fy = y - y0;
  auto texel = [&](int xi, int yi) {
    xi = t.wrap_s == scene::Texture::Wrap::kRepeat ? ((xi % w) + w) % w : std::clamp(xi, 0, w - 1);
    yi = t.wrap_t == scene::Texture::Wrap::kRepeat ? ((yi % h) + h) % h : std::clamp(yi, 0, h - 1);
    const float* p = t.rgba.at(xi, yi);
    return glm::vec4(p[0], p[1], p[2], p[3]);
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x0 + 1, y0)) +
         fy * ((1 - fx) * texel(x0, y0 + 1) + fx * texel(x0 + 1, y0 + 1));
}

// ---------------------------------------------------------------------------------------------
// Shadow map: orthographic depth from the key light, percentage-closer soft shadows

class ShadowMap {
 public:
  ShadowMap(const FrameGeometry& g, const glm::vec3& light, float softness_deg, int size) {
    Bounds casters;
    for (std::size_t i = 0; i < g.caster_indices; ++i) casters.add(g.pos[g.indices[i]]);
    if (casters.empty()) return;
    radius_ = std::max(1e-6f, 0.5f * glm::length(casters.size())) * 1.01f;
    proj_.cam.perspective = false;
    proj_.cam.ortho_half_height = radius_;
    const glm::vec3 c = casters.center();
    const glm::vec3 up = std::abs(light.y) > 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    proj_.cam.view = glm::lookAt(c + 2.0f * radius_ * light, c, up);
    proj_.width = proj_.height = size;
    size_ = size;
    texel_ = 2.0f * radius_ / size;
    tan_half_ =
        std::tan(0.5f * std::clamp(softness_deg, 0.0f, 45.0f) * std::numbers::pi_v<float> / 180.0f);
    std::vector<ClipVertex> verts(g.pos.size());
    for (std::size_t v = 0; v < g.pos.size(); ++v) verts[v] = proj_.clip(g.pos[v]);
    std::vector<uint32_t> idx(g.indices.begin(), g.indices.begin() + g.caster_indices);
    RasterOptions ro;
    ro.perspective = false;
    ro.znear = 1e-6f * radius_;
    ro.with_attributes = false;
    map_.reset(size, size, false);
    rasterize(verts, idx, ro, map_);
    // Nearest occluder per block of texels: most receivers see no occluder anywhere near and are
    // answered from a few blocks instead of a full blocker search.
    blocks_ = (size + kBlock - 1) / kBlock;
    block_min_.assign(std::size_t(blocks_) * blocks_, std::numeric_limits<float>::infinity());
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const float key = map_.key[map_.index(x, y)];
        if (std::isinf(key)) continue;
        float& m = block_min_[std::size_t(y / kBlock) * blocks_ + x / kBlock];
        m = std::min(m, -key);
      }
  }

  // 1 = fully lit by the key light, 0 = fully in its cast shadow. The depth bias grows with the
  // filter footprint times the surface's slope to the light, so a surface never shadows itself
  // (near the terminator a wide filter reaches points of the same surface nearer the light).
  float visibility(const glm::vec3& p, const glm::vec3& geometric_normal) const {
    if (size_ == 0) return 1.0f;
    const glm::vec3 q = p + geometric_normal * (1.5f * texel_);
    const ClipVertex c = proj_.clip(q);
    const float u = (c.x + 1.0f) * 0.5f * size_, v = (1.0f - c.y) * 0.5f * size_;
    const glm::vec3 l = glm::vec3(glm::transpose(proj_.cam.view)[2]);  // towards the light
    const float cos_l = std::clamp(std::abs(glm::dot(geometric_normal, l)), 0.05f, 1.0f);
    const float slope = std::min(std::sqrt(1.0f - cos_l * cos_l) / cos_l, 20.0f);
    auto biased = [&](float radius_texels) {
      return c.depth - texel_ * (1.5f + slope * (radius_texels + 1.0f));
    };
    if (tan_half_ <= 0.0f) return occluder(u, v) < biased(0.5f) ? 0.0f : 1.0f;
    // Blocker search over the largest penumbra the light could cast (occluder a whole caster
    // radius away), then a filter as wide as the penumbra at this receiver.
    const float search = std::clamp(tan_half_ * radius_ / texel_, 1.0f, 32.0f);
    const float d_search = biased(search);
    if (nearest_in(u - search, v - search, u + search, v + search) >= d_search) return 1.0f;
    float blockers = 0.0f;
    int n = 0;
    for (int j = -2; j <= 2; ++j)
      for (int i = -2; i <= 2; ++i) {
        const float o = occluder(u + 0.5f * i * search, v + 0.5f * j * search);
        if (o < d_search) blockers += o, ++n;
      }
    if (n == 0) return 1.0f;
    const float blocker = blockers / n;
    const float filter = std::clamp((c.depth - blocker) * tan_half_ / texel_, 0.5f, 32.0f);
    const float d = biased(filter);
    int lit = 0;
    for (int j = -3; j <= 3; ++j)
      for (int i = -3; i <= 3; ++i)
        if (occluder(u + (i / 3.0f) * filter, v + (j / 3.0f) * filter) >= d) ++lit;
    return lit / 49.0f;
  }

 private:
  // Depth of the nearest caster at a map position (infinity: none).
  float occluder(float u, float v) const {
    // Range-checked as floats first: converting a NaN or huge float to int is undefined.
    if (!(u >= 0.0f && v >= 0.0f && u < float(size_) && v < float(size_)))
      return std::numeric_limits<float>::infinity();
    const int x = int(std::floor(u)), y = int(std::floor(v));
    if (x < 0 || y < 0 || x >= size_ || y >= size_) return std::numeric_limits<float>::infinity();
    const float key = map_.key[map_.index(x, y)];
    return std::isinf(key) ? std::numeric_limits<float>::infinity() : -key;
  }

  Projector proj_;
  // The nearest occluder depth over the blocks touching a map rectangle.
  float nearest_in(float u0, float v0, float u1, float v1) const {
    // Clamped as floats before the int conversion (NaN becomes 0).
    const float hi = float(size_);
    auto clampf = [hi](float f) { return f >= 0.0f ? std::min(f, hi) : 0.0f; };
    u0 = clampf(u0), v0 = clampf(v0), u1 = clampf(u1), v1 = clampf(v1);
    const int bx0 = std::clamp(int(std::floor(u0)) / kBlock, 0, blocks_ - 1);
    const int by0 = std::clamp(int(std::floor(v0)) / kBlock, 0, blocks_ - 1);
    const int bx1 = std::clamp(int(std::floor(u1)) / kBlock, 0, blocks_ - 1);
    const int by1 = std::clamp(int(std::floor(v1)) / kBlock, 0, blocks_ - 1);
    float m = std::numeric_limits<float>::infinity();
    for (int by = by0; by <= by1; ++by)
      for (int bx = bx0; bx <= bx1; ++bx)
        m = std::min(m, block_min_[std::size_t(by) * blocks_ + bx]);
    return m;
  }

  static constexpr int kBlock = 16;
  VisibilityBuffer map_;
  std::vector<float> block_min_;
  int blocks_ = 0;
  int size_ = 0;
  float radius_ = 1.0f, texel_ = 1.0f, tan_half_ = 0.0f;
};

// ---------------------------------------------------------------------------------------------
// Outline: discontinuities between neighbouring samples, widened by a bounded distance field

struct OutlineTri {
  int object_id, material_id;
  glm::vec3 view_normal;  // plane of the triangle in view space: dot(n, p) = d
  float view_d;
  glm::vec3 face_normal;
};

void draw_outline(const VisibilityBuffer& vb, const FrameGeometry& g, const Projector& proj,
                  const RenderOptions& opt, Image<float>& frame) {
  if (opt.outline_width <= 0.0f) return;
  const int S = opt.aa;
  const int W = vb.width, H = vb.height;
  std::vector<OutlineTri> tris(g.tris.size());
  const glm::mat3 rot(proj.cam.view);
  for (std::size_t t = 0; t < g.tris.size(); ++t) {
    const glm::vec3 p0 = glm::vec3(proj.cam.view * glm::vec4(g.pos[g.indices[3 * t]], 1.0f));
    const glm::vec3 n = rot * g.tris[t].face_normal;
    tris[t] = {g.tris[t].object_id, g.tris[t].material_id, n, glm::dot(n, p0),
               g.tris[t].face_normal};
  }
  const float cos_crease =
      std::cos(std::clamp(opt.crease_deg, 0.0f, 180.0f) * std::numbers::pi_v<float> / 180.0f);
  const float jump = opt.depth_jump;
  // Relative error of predicting sample b's depth from the plane of sample a's triangle.
  auto plane_error = [&](const OutlineTri& ta, int bx, int by, float depth_b) {
    glm::vec3 o, d;
    proj.ray((bx + 0.5f) / S, (by + 0.5f) / S, o, d);
    const float denom = glm::dot(ta.view_normal, d);
    if (std::abs(denom) < 1e-12f) return std::numeric_limits<float>::infinity();
    const float t = (ta.view_d - glm::dot(ta.view_normal, o)) / denom;
    return std::abs(t - depth_b) / std::max(depth_b, 1e-12f);
  };
  // 0: no line between the two samples, 1: silhouette / depth jump / id boundary, 2: crease.
  auto edge = [&](int ax, int ay, int bx, int by) -> uint8_t {
    const std::size_t ia = vb.index(ax, ay), ib = vb.index(bx, by);
    const int32_t a = vb.tri[ia], b = vb.tri[ib];
    if (a == b) return 0;
    const int oa = a < 0 ? 0 : tris[a].object_id, ob = b < 0 ? 0 : tris[b].object_id;
    // The ground's far edge against the background is not a line anyone wants.
    if ((oa == 0 && ob == kGroundObject) || (ob == 0 && oa == kGroundObject)) return 0;
    if (a < 0 || b < 0) return 1;
    if (oa != ob || tris[a].material_id != tris[b].material_id) return 1;
    const float da = proj.depth_from_key(vb.key[ia]), db = proj.depth_from_key(vb.key[ib]);
    const float err = std::min(plane_error(tris[a], bx, by, db), plane_error(tris[b], ax, ay, da));
    if (err > jump) return 1;
    return glm::dot(tris[a].face_normal, tris[b].face_normal) < cos_crease ? 2 : 0;
  };
  // Each sample records its edges to the right (bits 0-1) and below (bits 2-3); a sample is on a
  // line when it differs from any of its four neighbours (both sides are marked, so lines centre
  // on the boundary).
  std::vector<uint8_t> bits(std::size_t(W) * H, 0);
  parallel_rows(H, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        uint8_t b = 0;
        if (x + 1 < W) b |= edge(x, y, x + 1, y);
        if (y + 1 < H) b |= edge(x, y, x, y + 1) << 2;
        bits[vb.index(x, y)] = b;
      }
  });
  // mark: 1 on a silhouette / id line, 2 on a crease only.
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
  // A crease mark with almost no marked samples around it is where a few faces meet at a
  // vertex, not a crease line: it would print as a speck, so it is dropped.
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
  const float half_width = 0.5f * opt.outline_width * S;  // in samples
  const int reach = int(std::ceil(half_width)) + 1;
  const float far = float(reach + 1);
  // Horizontal distance to the nearest marked sample in the row, capped.
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
  // Which (sample row, pixel column) spans hold any sample near a line: most pixels have none in
  // their vertical window and are skipped.
  const int Wp = frame.width(), Hp = frame.height();
  std::vector<uint8_t> near(std::size_t(H) * Wp, 0);
  parallel_rows(H, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int px = 0; px < Wp; ++px)
        for (int sx = px * S; sx < (px + 1) * S; ++sx)
          if (hdist[std::size_t(y) * W + sx] < far) near[std::size_t(y) * Wp + px] = 1;
  });
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

}  // namespace

// ---------------------------------------------------------------------------------------------
// ShotRenderer

ShotRenderer::ShotRenderer(const scene::Scene& scene, const scene::ShotSpec& shot,
                           const RenderOptions& options)
    : scene_(scene), shot_(shot), options_(options) {
  CHECK_GT(options_.width, 0);
  CHECK_GT(options_.height, 0);
  options_.aa = std::clamp(options_.aa, 1, 4);
  // The visibility buffer holds 16 bytes per sample for the whole frame.
  const double samples = double(options_.width) * options_.height * options_.aa * options_.aa;
  if (samples > kMaxSamples)
    throw Error(Error::Field{"aa"},
                fmt::format("{}x{} pixels with {}x{} samples each need {:.1f} GB of sample "
                            "buffers (limit {:.1f} GB); lower the antialiasing or the size",
                            options_.width, options_.height, options_.aa, options_.aa,
                            samples * 16 / 1e9, kMaxSamples * 16 / 1e9));
  // Front ends check these with their own names; this is the last line for any other caller.
  if (!(shot_.fps >= kMinFps && shot_.fps <= kMaxFps))
    throw Error(Error::Field{"fps"},
                fmt::format("must be in [{}, {}], got {}", kMinFps, kMaxFps, shot_.fps));
  if (!std::isfinite(shot_.start_time) || shot_.start_time < 0.0f)
    throw Error(Error::Field{"start"},
                fmt::format("must be a finite number >= 0, got {}", shot_.start_time));
  if (!shot_.clip.empty()) {
    animation_ = scene.find_animation(shot_.clip);
    if (animation_ < 0) {
      // Names come from the scene and the command line: each is echoed capped, and few.
      std::string names;
      for (std::size_t i = 0; i < scene.animations.size() && i < 16; ++i)
        names += (names.empty() ? "'" : ", '") + echo(scene.animations[i].name, 40) + "'";
      if (scene.animations.size() > 16)
        names += fmt::format(", ... ({} more)", scene.animations.size() - 16);
      throw Error(Error::Field{"clip"},
                  fmt::format("no clip '{}' in the scene (clips: {})", echo(shot_.clip),
                              names.empty() ? "none" : names));
    }
  } else if (!scene.animations.empty()) {
    animation_ = 0;
  }
  // Bounded before any loop over the range: f - 1, (first + last) / 2 and the loops below then
  // never overflow, and --frames 2147483647 --loop is refused instead of spinning forever.
  if (shot_.first_frame < 0 || shot_.last_frame < shot_.first_frame ||
      shot_.last_frame > kMaxFrame || shot_.last_frame - shot_.first_frame >= kMaxFrameCount)
    throw Error(Error::Field{"frames"},
                fmt::format("invalid frame range {}-{} (frames in [0, {}], at most {} of them)",
                            shot_.first_frame, shot_.last_frame, kMaxFrame, kMaxFrameCount));
  if (animation_ >= 0) {
    const scene::Animation& a = scene.animations[animation_];
    const float duration = a.end - a.start;
    if (!std::isfinite(duration))
      throw Error(Error::Field{"clip"},
                  fmt::format("clip '{}' has no finite length", echo(a.name)));
    if (shot_.start_time > duration)
      throw Error(Error::Field{"start"}, fmt::format("{} s is outside clip '{}' ({:.3f} s long)",
                                                     shot_.start_time, echo(a.name), duration));
    // In double and clamped: a clip of 1e30 s must not overflow the int.
    const double frames_in_clip =
        std::floor((double(duration) - shot_.start_time) * shot_.fps + 1e-3);
    const int last_frame = int(std::min<double>(frames_in_clip, kMaxFrame));
    if (!shot_.loop && shot_.last_frame > last_frame)
      throw Error(
          Error::Field{"frames"},
          fmt::format("frame {} is at {:.3f} s, past the end of clip '{}' "
                      "({:.3f} s long: frames 0-{} at {} fps from {} s; a looping clip may run "
                      "past its end)",
                      shot_.last_frame, shot_.start_time + shot_.last_frame / shot_.fps,
                      echo(a.name), duration, last_frame, shot_.fps, shot_.start_time));
  }
  if (shot_.camera.mode == scene::CameraSpec::Mode::kGltf) {
    const int n = shot_.camera.gltf_node;
    if (n < 0 || n >= int(scene.nodes.size()) || scene.nodes[n].camera < 0)
      throw Error(Error::Field{"gltf_node"}, fmt::format("node {} is not a camera node", n));
  }
  // The boxes are fixed for the shot, so normalised values compare across frames. They come
  // from every frame of a range up to kMaxBoundsFrames long (so results do not change for any
  // ordinary shot) and from kMaxBoundsFrames evenly spread frames of a longer one: the work
  // before the first frame renders must not grow with a million-frame range.
  const int first = shot_.first_frame, last = shot_.last_frame;
  const int mid = first + (last - first) / 2;
  const int64_t count = int64_t(last) - first + 1;
  std::vector<int> frames;
  if (count <= kMaxBoundsFrames) {
    for (int f = first; f <= last; ++f) frames.push_back(f);
  } else {
    for (int64_t k = 0; k < kMaxBoundsFrames; ++k)
      frames.push_back(int(first + (count - 1) * k / (kMaxBoundsFrames - 1)));
    frames.push_back(mid);  // the middle pose frames the camera below
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  }
  for (const int f : frames) {
    const scene::PosedScene posed = scene::pose_scene(scene, animation_, time_of(float(f)));
    shot_bounds_.add(scene::world_bounds(posed));
    if (f == first) rest_box_ = cube_around(scene::rest_bounds(posed));
    // A few poses' vertices (first, middle, last frame; at most ~20k points) for framing.
    if (f == first || f == mid || f == last) {
      std::size_t total = 0;
      for (const auto& p : posed.primitives) total += p.world_positions.size();
      const std::size_t step = std::max<std::size_t>(1, total / 20000);
      std::size_t i = 0;
      for (const auto& p : posed.primitives)
        for (const glm::vec3& v : p.world_positions)
          if (i++ % step == 0) fit_points_.push_back(v);
    }
  }
  position_box_ = cube_around(shot_bounds_);
  // Just under the lowest point, so an object's flat bottom does not z-fight with the ground.
  ground_height_ = shot_.ground.auto_height && !shot_bounds_.empty()
                       ? shot_bounds_.lo.y - 1e-4f * glm::length(shot_bounds_.size())
                       : shot_.ground.height;
  light_ = scene::light_direction(shot_, camera(float(shot_.first_frame)));
}

float ShotRenderer::time_of(float frame) const {
  if (animation_ < 0) return shot_.start_time + frame / shot_.fps;
  const scene::Animation& a = scene_.animations[animation_];
  double t = double(shot_.start_time) + double(frame) / shot_.fps;
  const double duration = double(a.end) - a.start;
  // Wrapped in double, so frame f and f + one cycle land on the same clip time.
  if (shot_.loop && duration > 0.0) t -= std::floor(t / duration) * duration;
  return a.start + float(t);
}

scene::ViewCamera ShotRenderer::camera(float frame) const {
  const float aspect = float(options_.width) / float(options_.height);
  scene::Pose pose;
  if (shot_.camera.mode == scene::CameraSpec::Mode::kGltf)
    pose = scene::evaluate_pose(scene_, animation_, time_of(frame));
  return scene::camera_at(shot_, scene_, pose, shot_bounds_, frame, aspect, &fit_points_);
}

Image<float> ShotRenderer::render(int frame) const {
  const int W = options_.width, H = options_.height, S = options_.aa;
  const scene::PosedScene cur = scene::pose_scene(scene_, animation_, time_of(frame));
  const scene::PosedScene prev = scene::pose_scene(scene_, animation_, time_of(frame - 1));
  const FrameGeometry g = build_geometry(scene_, cur, prev, position_box_, rest_box_, shot_.ground,
                                         ground_height_, shot_bounds_);
  Projector proj{camera(float(frame)), float(W) / float(H), W, H};
  Projector prev_proj{camera(float(frame - 1)), float(W) / float(H), W, H};

  VisibilityBuffer vb;
  vb.reset(W * S, H * S, true);
  {
    std::vector<ClipVertex> verts(g.pos.size());
    for (std::size_t v = 0; v < g.pos.size(); ++v) verts[v] = proj.clip(g.pos[v]);
    RasterOptions ro;
    ro.perspective = proj.cam.perspective;
    ro.znear = proj.cam.znear;
    rasterize(verts, g.indices, ro, vb);
  }
  const ShadowMap shadow(g, light_, shot_.light.softness_deg, options_.shadow_map_size);

  Image<float> out(W, H, kChannelCount);
  const glm::mat3 view_rot(proj.cam.view);
  const glm::vec3 eye = proj.cam.position();
  const glm::vec3 forward = glm::transpose(view_rot) * glm::vec3(0, 0, -1);
  const glm::vec3 L = light_;
  const glm::vec3 background = shot_.background;

  parallel_rows(H, 4, [&](int y0, int y1) {
    struct Hit {
      int32_t tri;
      int count;
      float b1, b2;
    };
    Hit hits[16];
    for (int y = y0; y < y1; ++y) {
      for (int x = 0; x < W; ++x) {
        int n_hits = 0, covered = 0;
        for (int sy = y * S; sy < (y + 1) * S; ++sy)
          for (int sx = x * S; sx < (x + 1) * S; ++sx) {
            const std::size_t i = vb.index(sx, sy);
            const int32_t t = vb.tri[i];
            if (t < 0) continue;
            ++covered;
            int k = 0;
            while (k < n_hits && hits[k].tri != t) ++k;
            if (k == n_hits) hits[n_hits++] = {t, 0, 0.0f, 0.0f};
            hits[k].count++;
            hits[k].b1 += vb.b1[i];
            hits[k].b2 += vb.b2[i];
          }
        float* o = out.at(x, y);
        if (covered == 0) {
          for (int c = 0; c < 3; ++c) o[kAlbedo + c] = background[c];
          continue;
        }
        glm::vec3 normal(0.0f), position(0.0f), rest(0.0f), albedo(0.0f);
        glm::vec2 motion(0.0f);
        float depth = 0.0f, diffuse = 0.0f, shadow_mask = 0.0f;
        // Ids: the object covering the most samples (background included), then its material
        // covering the most samples; ties keep the first in sample order.
        int best_object = 0, best_material = 0, best_count = S * S - covered;
        for (int k = 0; k < n_hits; ++k) {
          const int id = g.tris[hits[k].tri].object_id;
          int count = 0;
          for (int j = 0; j < n_hits; ++j)
            if (g.tris[hits[j].tri].object_id == id) count += hits[j].count;
          if (count > best_count) best_count = count, best_object = id;
        }
        for (int k = 0, best_m = 0; k < n_hits; ++k) {
          const TriInfo& info = g.tris[hits[k].tri];
          if (info.object_id != best_object) continue;
          int count = 0;
          for (int j = 0; j < n_hits; ++j)
            if (g.tris[hits[j].tri].object_id == best_object &&
                g.tris[hits[j].tri].material_id == info.material_id)
              count += hits[j].count;
          if (count > best_m) best_m = count, best_material = info.material_id;
        }
        for (int k = 0; k < n_hits; ++k) {
          const Hit& h = hits[k];
          const TriInfo& info = g.tris[h.tri];
          const float weight = float(h.count) / float(covered);
          const float b1 = h.b1 / h.count, b2 = h.b2 / h.count, b0 = 1.0f - b1 - b2;
          const uint32_t i0 = g.indices[3 * h.tri], i1 = g.indices[3 * h.tri + 1],
                         i2 = g.indices[3 * h.tri + 2];
          const glm::vec3 p = b0 * g.pos[i0] + b1 * g.pos[i1] + b2 * g.pos[i2];
          const glm::vec3 pp = b0 * g.prev_pos[i0] + b1 * g.prev_pos[i1] + b2 * g.prev_pos[i2];
          glm::vec3 n = b0 * g.normal[i0] + b1 * g.normal[i1] + b2 * g.normal[i2];
          n = glm::length(n) > 0.0f ? glm::normalize(n) : info.face_normal;
          glm::vec3 fn = info.face_normal;
          // A back face seen from the camera is shaded as the surface the viewer sees.
          const glm::vec3 to_eye = proj.cam.perspective ? eye - p : -forward;
          if (glm::dot(fn, to_eye) < 0.0f) fn = -fn, n = -n;
          normal += weight * (view_rot * n);
          position += weight * p;
          rest += weight * (b0 * g.rest[i0] + b1 * g.rest[i1] + b2 * g.rest[i2]);
          depth += weight * -(proj.cam.view * glm::vec4(p, 1.0f)).z;
          motion += weight * (prev_proj.pixel(pp) - proj.pixel(p));
          glm::vec3 base = g.ground_color;
          if (info.object_id != kGroundObject) {
            base = glm::vec3(1.0f);
            if (info.material) {
              glm::vec4 c = info.material->base_color;
              if (info.material->base_color_texture >= 0) {
                const glm::vec2 uv = b0 * g.uv[i0] + b1 * g.uv[i1] + b2 * g.uv[i2];
                c *= sample_texture(scene_.textures[info.material->base_color_texture], uv);
              }
              base = glm::vec3(c);
            }
          }
          albedo += weight * base;
          const float ndl = glm::dot(n, L);
          float vis = 0.0f;
          if (ndl > 0.0f || glm::dot(fn, L) > 0.0f) vis = shadow.visibility(p, fn);
          diffuse += weight * std::max(0.0f, ndl) * vis;
          // Cast shadow only: surfaces turned from the light are dark in `diffuse` already.
          shadow_mask += weight * (1.0f - vis) * std::clamp(ndl * 10.0f, 0.0f, 1.0f);
        }
        const float len = glm::length(normal);
        normal = len > 0.0f ? normal / len : glm::vec3(0, 0, 1);
        for (int c = 0; c < 3; ++c) {
          o[kNormal + c] = normal[c];
          o[kPosition + c] = position[c];
          o[kPositionNorm + c] = normalise_in(position_box_, position)[c];
          o[kRestPosition + c] = rest[c];
          o[kAlbedo + c] = albedo[c];
        }
        o[kDepth] = depth;
        o[kDiffuse] = diffuse;
        o[kShadow] = shadow_mask;
        o[kObjectId] = float(best_object);
        o[kMaterialId] = float(best_material);
        o[kMotion] = motion.x;
        o[kMotion + 1] = motion.y;
        o[kAlpha] = float(covered) / float(S * S);
      }
    }
  });
  draw_outline(vb, g, proj, options_, out);
  return out;
}

float object_coverage(ImageView<const float> frame) {
  double sum = 0.0;
  for (int y = 0; y < frame.height; ++y)
    for (int x = 0; x < frame.width; ++x)
      if (frame(x, y, kObjectId) >= float(kFirstSceneId)) sum += 1.0;
  return float(sum / (double(frame.width) * frame.height));
}

}  // namespace emaki::render
