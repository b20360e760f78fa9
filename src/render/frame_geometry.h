// Internals of the renderer (renderer.h) shared by its source files, not for other modules:
// the camera projection, one frame's posed triangles and the texture lookup
// (frame_geometry.cpp), the key light's shadow map (shadow_map.h) and the outline pass
// (outline.h).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "render/raster.h"
#include "scene/scene.h"
#include "scene/staging.h"

namespace emaki::render::detail {

// Object and material ids of the passes: 0 is the background.
constexpr int kGroundObject = 1;
constexpr int kGroundMaterial = 1;
constexpr int kFirstSceneId = 2;

inline glm::vec3 normalise_in(const scene::Bounds& cube, const glm::vec3& p) {
  return (p - cube.lo) / (cube.hi.x - cube.lo.x);
}

// ---------------------------------------------------------------------------------------------
// Projection

struct Projector {
  scene::ViewCamera cam;
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

// The scene's triangles posed at this frame (`cur`) and the previous one (`prev`), then the
// ground quad when the shot has one (it casts no shadow: it comes after caster_indices).
FrameGeometry build_geometry(const scene::Scene& scene, const scene::PosedScene& cur,
                             const scene::PosedScene& prev, const scene::Bounds& position_box,
                             const scene::Bounds& rest_box, const scene::GroundSpec& ground,
                             float ground_height, const scene::Bounds& shot_bounds);

// Bilinear lookup with the texture's wrap modes.
glm::vec4 sample_texture(const scene::Texture& t, glm::vec2 uv);

}  // namespace emaki::render::detail
