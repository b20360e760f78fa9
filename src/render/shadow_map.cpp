#include "render/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <numbers>

namespace emaki::render::detail {

using scene::Bounds;

ShadowMap::ShadowMap(const FrameGeometry& g, const glm::vec3& light, float softness_deg, int size) {
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
float ShadowMap::visibility(const glm::vec3& p, const glm::vec3& geometric_normal) const {
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

// Depth of the nearest caster at a map position (infinity: none).
float ShadowMap::occluder(float u, float v) const {
  // Range-checked as floats first: converting a NaN or huge float to int is undefined.
  if (!(u >= 0.0f && v >= 0.0f && u < float(size_) && v < float(size_)))
    return std::numeric_limits<float>::infinity();
  const int x = int(std::floor(u)), y = int(std::floor(v));
  if (x < 0 || y < 0 || x >= size_ || y >= size_) return std::numeric_limits<float>::infinity();
  const float key = map_.key[map_.index(x, y)];
  return std::isinf(key) ? std::numeric_limits<float>::infinity() : -key;
}

// The nearest occluder depth over the blocks touching a map rectangle.
float ShadowMap::nearest_in(float u0, float v0, float u1, float v1) const {
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
    for (int bx = bx0; bx <= bx1; ++bx) m = std::min(m, block_min_[std::size_t(by) * blocks_ + bx]);
  return m;
}

}  // namespace emaki::render::detail
