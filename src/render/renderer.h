// The guide-pass renderer: rasterises a Scene posed at a shot's frames into the passes of
// passes.h, on the CPU, in linear float, with supersampling (continuous passes average the
// covered samples, ids take the dominant one, alpha counts coverage).
#pragma once

#include <string>
#include <vector>

#include "core/image.h"
#include "render/passes.h"
#include "scene/scene.h"
#include "scene/staging.h"

namespace emaki::render {

// Frame rates a shot may play at (`--fps`); outside them frame times lose all precision.
inline constexpr float kMinFps = 0.01f;
inline constexpr float kMaxFps = 1000.0f;

struct RenderOptions {
  int width = 640;             // pixels, [1, 16384]
  int height = 360;            // pixels, [1, 16384]
  int aa = 2;                  // samples per pixel side (aa x aa per pixel), [1, 4]
  float outline_width = 1.5f;  // line width in pixels, [0, 16]; 0 = no lines
  float crease_deg = 45.0f;    // angle between face normals drawn as a crease, [0, 180]
  float depth_jump = 0.03f;    // relative depth gap drawn as a silhouette line, (0, 1]
  int shadow_map_size = 2048;  // texels per side, [64, 8192]
};

// Renders the frames of one shot. Everything fixed for the shot (the clip, the normalisation
// boxes, the light) is decided once, at construction, so a frame's values compare with every
// other frame's.
class ShotRenderer {
 public:
  // Throws emaki::Error naming a field (Error::Field; front ends re-spell it) for a clip that is
  // not in the scene ("clip"), a start time or frame range that leaves the clip ("start",
  // "frames"), a node that is not a camera ("gltf_node") or more samples than the sample buffers
  // allow ("aa"). `scene` must outlive the renderer.
  ShotRenderer(const scene::Scene& scene, const scene::ShotSpec& shot,
               const RenderOptions& options);

  // The kChannelCount-channel frame (see passes.h).
  Image<float> render(int frame) const;

  // The clip time of a frame: clip start + start_time + frame / fps (wrapped when looping).
  float time_of(float frame) const;
  int animation() const { return animation_; }
  const scene::Bounds& position_box() const { return position_box_; }
  const scene::Bounds& rest_box() const { return rest_box_; }
  // The light at the first frame (LightSpec::turn_deg turns it over the range; render() uses
  // each frame's).
  const glm::vec3& light() const { return light_; }
  // The camera at a frame (fractional frames allowed; motion uses frame - 1).
  scene::ViewCamera camera(float frame) const;

 private:
  const scene::Scene& scene_;
  scene::ShotSpec shot_;
  RenderOptions options_;
  int animation_ = -1;
  scene::Bounds shot_bounds_;          // world bounds of the objects over the frame range
  scene::Bounds position_box_;         // cube around shot_bounds_
  scene::Bounds rest_box_;             // cube around the rest-pose bounds
  std::vector<glm::vec3> fit_points_;  // vertices over the shot, framed by the automatic camera
  float ground_height_ = 0.0f;
  scene::ViewCamera first_camera_;  // resolves a camera-relative light direction
  glm::vec3 light_{0, 1, 0};
};

// Fraction of the frame's pixels covered by scene objects (ground and background excluded).
float object_coverage(ImageView<const float> frame);

}  // namespace emaki::render
