// One frame's posed triangles for the rasteriser, and the texture lookup of the albedo pass.
#include "render/frame_geometry.h"

#include <algorithm>
#include <cmath>

namespace emaki::render::detail {

using scene::Bounds;

namespace {

// A square ground quad at `ground_height` under the shot: `ground.size` wide, or six times the
// shot's horizontal extent when that is 0.
void add_ground(FrameGeometry& g, const Bounds& position_box, const scene::GroundSpec& ground,
                float ground_height, const Bounds& shot_bounds) {
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

}  // namespace

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
  if (ground.enabled) add_ground(g, position_box, ground, ground_height, shot_bounds);
  return g;
}

glm::vec4 sample_texture(const scene::Texture& t, glm::vec2 uv) {
  const Image<float>& rgba = *t.rgba;
  const int w = rgba.width(), h = rgba.height();
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
    const float* p = rgba.at(xi, yi);
    return glm::vec4(p[0], p[1], p[2], p[3]);
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x0 + 1, y0)) +
         fy * ((1 - fx) * texel(x0, y0 + 1) + fx * texel(x0 + 1, y0 + 1));
}

}  // namespace emaki::render::detail
