// What a shot adds to a scene file: camera (fixed, or orbit / dolly / pan over the frame range),
// a directional key light, an optional ground plane, a background colour, the clip and frame
// range. Filled from `emaki render`'s options, a shot file's source.* keys or the reference
// sphere (exemplar::reference_shot); resolved per frame into a ViewCamera.
#pragma once

#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace emaki::scene {

// The automatic camera's default elevation, degrees above the horizon (source.camera.elevation,
// `emaki render --elevation`, emaki.render(elevation=)).
inline constexpr float kDefaultAutoElevationDeg = 15.0f;

struct CameraSpec {
  enum class Mode {
    kAuto,    // look at the shot's bounds from (azimuth, elevation), distance fitted to them
    kLookAt,  // from `position` towards `target`
    kGltf,    // the glTF camera on node `gltf_node`, animated with the clip
  };
  Mode mode = Mode::kAuto;
  glm::vec3 position{0.0f, 0.0f, 5.0f};
  glm::vec3 target{0.0f};
  bool has_target = false;    // kAuto: aim at `target` instead of the bounds' centre
  float azimuth_deg = 30.0f;  // kAuto: around +Y, 0 = looking from +Z (glTF front)
  float elevation_deg = kDefaultAutoElevationDeg;  // kAuto: above the horizon
  float distance = 0.0f;                           // kAuto: 0 = fit the bounds
  float fov_deg = 40.0f;  // vertical field of view, degrees; camera_at clamps to [0.1, 170]
  bool orthographic = false;
  float ortho_height = 0.0f;  // full visible height in scene units; 0 = fit the shot's bounds
  int gltf_node = -1;
  // Motion from the first to the last frame of the range (linear, extrapolated outside it).
  float orbit_deg = 0.0f;  // turn around the target about +Y
  float dolly = 1.0f;      // distance to the target is multiplied by this at the last frame
  glm::vec3 pan{0.0f};     // camera and target move by this
  // Principal point offset in NDC units (x right, y up; 1 = half the image): lens shift, used to
  // put an on-axis sphere at an off-centre spot of a painting.
  glm::vec2 shift{0.0f};
};

struct LightSpec {
  // Direction towards the light. Camera-relative directions (x right, y up, z towards the
  // viewer) are turned into world space with the camera of the first frame and then held fixed.
  glm::vec3 direction{-1.0f, 1.0f, 1.0f};
  bool camera_relative = true;
  float softness_deg = 2.0f;  // angular size of the light: widens the shadow penumbra, [0, 45]
  // Degrees the light turns about world +Y from the first to the last frame of the range
  // (linear, extrapolated outside it, as the camera's orbit): a sun that moves, shadows that
  // sweep across the ground.
  float turn_deg = 0.0f;
};

struct GroundSpec {
  bool enabled = true;
  float size = 0.0f;        // side of the square; 0 = 6x the bounds' larger horizontal side
  float height = 0.0f;      // y of the plane
  bool auto_height = true;  // put it under the lowest point of the shot
  glm::vec3 color{0.8f};    // linear albedo
};

struct ShotSpec {
  CameraSpec camera;
  LightSpec light;
  GroundSpec ground;
  glm::vec3 background{0.0f};
  std::string clip;  // animation name; empty = the first clip, if any
  float fps = 24.0f;
  float start_time = 0.0f;  // seconds into the clip of frame 0, [0, clip length]
  int first_frame = 0;      // frame f is at time clip.start + start_time + f / fps
  int last_frame = 0;
  // Play the clip in a loop: clip time wraps around its length, so a walk cycle covers any frame
  // range. Off: a frame past the clip's end is an error.
  bool loop = false;
};

// A resolved camera: world -> camera (looking down -Z, +Y up) and projection parameters.
struct ViewCamera {
  glm::mat4 view{1.0f};
  bool perspective = true;
  float tan_half_fov = 0.364f;  // tan(vertical fov / 2)
  float ortho_half_height = 1.0f;
  glm::vec2 shift{0.0f};
  float znear = 0.01f;
  glm::vec3 position() const;
};

// The camera at `frame` (fractional frames allowed). `bounds` are the shot's world bounds
// (union over the frame range); `pose` is the scene's pose at that frame (for glTF cameras).
// The automatic camera's distance frames `fit_points` (e.g. the objects' vertices over the shot)
// when given, else the corners of `bounds`.
ViewCamera camera_at(const ShotSpec& shot, const Scene& scene, const Pose& pose,
                     const Bounds& bounds, float frame, float aspect,
                     const std::vector<glm::vec3>* fit_points = nullptr);

// The key light direction (unit, towards the light) in world space at `frame` (fractional frames
// allowed): `direction` resolved with the first frame's camera, turned by LightSpec::turn_deg.
glm::vec3 light_direction(const ShotSpec& shot, const ViewCamera& first_camera, float frame);

}  // namespace emaki::scene
