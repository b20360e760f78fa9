// The key light's shadow map for the diffuse and shadow passes: orthographic depth from the
// light over the frame's casters, percentage-closer soft shadows (renderer internals).
#pragma once

#include <vector>

#include "render/frame_geometry.h"
#include "render/raster.h"

namespace emaki::render::detail {

class ShadowMap {
 public:
  // Draws the casters of `g` (not the ground) seen from direction `light`; `softness_deg` is the
  // light's angular size, 0 for hard shadows.
  ShadowMap(const FrameGeometry& g, const glm::vec3& light, float softness_deg, int size);

  // 1 = fully lit by the key light, 0 = fully in its cast shadow.
  float visibility(const glm::vec3& p, const glm::vec3& geometric_normal) const;

 private:
  float occluder(float u, float v) const;
  float nearest_in(float u0, float v0, float u1, float v1) const;

  static constexpr int kBlock = 16;
  Projector proj_;
  VisibilityBuffer map_;
  std::vector<float> block_min_;  // nearest occluder per kBlock x kBlock block of texels
  int blocks_ = 0;
  int size_ = 0;
  float radius_ = 1.0f, texel_ = 1.0f, tan_half_ = 0.0f;
};

}  // namespace emaki::render::detail
