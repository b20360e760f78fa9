#include "scene/staging.h"

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <vector>

namespace emaki::scene {

glm::vec3 ViewCamera::position() const {
  return glm::vec3(glm::inverse(view)[3]);
}

namespace {
constexpr float kDeg = std::numbers::pi_v<float> / 180.0f;

glm::mat4 look_at(const glm::vec3& eye, const glm::vec3& target) {
  glm::vec3 fwd = target - eye;
  if (glm::length(fwd) < 1e-12f) fwd = glm::vec3(0, 0, -1);
  fwd = glm::normalize(fwd);
  // Looking straight up or down: any horizontal "up" keeps the view defined.
  const glm::vec3 up = std::abs(fwd.y) > 0.9999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  return glm::lookAt(eye, eye + fwd, up);
}

// A glTF camera: its node's world transform without scale, its projection; the near plane no
// closer than the shot's scale allows.
void gltf_camera(const CameraSpec& spec, const Scene& scene, const Pose& pose, float radius,
                 ViewCamera& cam) {
  const Node& node = scene.nodes.at(spec.gltf_node);
  const CameraDef& def = scene.cameras.at(node.camera);
  glm::mat4 world = pose.world.at(spec.gltf_node);
  // Drop scale from the node: a camera's frame is rigid.
  for (int c = 0; c < 3; ++c) world[c] = glm::vec4(glm::normalize(glm::vec3(world[c])), 0.0f);
  cam.view = glm::inverse(world);
  cam.perspective = def.perspective;
  cam.tan_half_fov = std::tan(0.5f * def.yfov);
  cam.ortho_half_height = def.ymag;
  cam.znear = std::max(def.znear, radius * 1e-4f);
}

// The automatic camera's distance from `target` along `dir`: the nearest at which every fit
// point (or the bounds' eight corners) falls inside 90 % of the frame: a point at depth
// dist - z needs |x| / depth and |y| / depth small.
float fit_distance(const CameraSpec& spec, const Bounds& bounds, const glm::vec3& target,
                   const glm::vec3& dir, float radius, float tan_half_fov, float aspect,
                   const std::vector<glm::vec3>* fit_points) {
  const glm::vec3 back = dir;
  const glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0, 1, 0), back));
  const glm::vec3 up = glm::cross(back, right);
  const float m = 0.9f;
  std::vector<glm::vec3> corners;
  if (!fit_points || fit_points->empty()) {
    for (int k = 0; k < 8; ++k)
      corners.emplace_back((k & 1) ? bounds.hi.x : bounds.lo.x, (k & 2) ? bounds.hi.y : bounds.lo.y,
                           (k & 4) ? bounds.hi.z : bounds.lo.z);
  }
  const std::vector<glm::vec3>& points = corners.empty() ? *fit_points : corners;
  float dist = 0.0f;
  for (const glm::vec3& c : points) {
    const glm::vec3 d = c - target;
    const float z = glm::dot(d, back);
    float need;
    if (spec.orthographic) {
      need = z + radius;
    } else {
      need = z + std::max(std::abs(glm::dot(d, right)) / (m * tan_half_fov * aspect),
                          std::abs(glm::dot(d, up)) / (m * tan_half_fov));
    }
    dist = std::max(dist, need);
  }
  return std::max(dist, 1e-3f * radius);
}
}  // namespace

ViewCamera camera_at(const ShotSpec& shot, const Scene& scene, const Pose& pose,
                     const Bounds& bounds, float frame, float aspect,
                     const std::vector<glm::vec3>* fit_points) {
  const CameraSpec& spec = shot.camera;
  ViewCamera cam;
  cam.shift = spec.shift;
  const glm::vec3 center = bounds.empty() ? glm::vec3(0.0f) : bounds.center();
  const float radius = bounds.empty() ? 1.0f : std::max(1e-6f, 0.5f * glm::length(bounds.size()));
  if (spec.mode == CameraSpec::Mode::kGltf) {
    gltf_camera(spec, scene, pose, radius, cam);
    return cam;
  }

  glm::vec3 target =
      spec.has_target || spec.mode == CameraSpec::Mode::kLookAt ? spec.target : center;
  glm::vec3 eye;
  const float half_fov = 0.5f * std::clamp(spec.fov_deg, 0.1f, 170.0f) * kDeg;
  cam.tan_half_fov = std::tan(half_fov);
  if (spec.mode == CameraSpec::Mode::kLookAt) {
    eye = spec.position;
  } else {
    const float az = spec.azimuth_deg * kDeg, el = spec.elevation_deg * kDeg;
    const glm::vec3 dir(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
    float dist = spec.distance;
    if (dist <= 0.0f && !bounds.empty())
      dist = fit_distance(spec, bounds, target, dir, radius, cam.tan_half_fov, aspect, fit_points);
    else if (dist <= 0.0f)
      dist = 1.05f * radius / std::sin(half_fov);
    eye = target + dist * dir;
  }

  // Orbit, dolly and pan run linearly over the frame range.
  const float span = float(std::max(1, shot.last_frame - shot.first_frame));
  const float u =
      shot.last_frame > shot.first_frame ? (frame - float(shot.first_frame)) / span : 0.0f;
  glm::vec3 offset = eye - target;
  if (spec.orbit_deg != 0.0f) {
    const float a = spec.orbit_deg * kDeg * u;
    offset = glm::vec3(std::cos(a) * offset.x + std::sin(a) * offset.z, offset.y,
                       -std::sin(a) * offset.x + std::cos(a) * offset.z);
  }
  offset *= 1.0f + (spec.dolly - 1.0f) * u;
  target += spec.pan * u;
  eye = target + offset;

  cam.view = look_at(eye, target);
  cam.perspective = !spec.orthographic;
  cam.ortho_half_height = spec.ortho_height > 0.0f ? 0.5f * spec.ortho_height : 1.05f * radius;
  // Near plane: a small fraction of the distance to the subject keeps depth precise while
  // clipping almost nothing.
  cam.znear = std::max(1e-4f * radius, 1e-3f * glm::length(offset));
  return cam;
}

glm::vec3 light_direction(const ShotSpec& shot, const ViewCamera& first_camera, float frame) {
  glm::vec3 d = shot.light.direction;
  if (glm::length(d) < 1e-12f) d = glm::vec3(0, 1, 0);
  d = glm::normalize(d);
  if (shot.light.camera_relative)
    d = glm::normalize(glm::transpose(glm::mat3(first_camera.view)) * d);
  if (shot.light.turn_deg == 0.0f || shot.last_frame <= shot.first_frame) return d;
  const float u = (frame - float(shot.first_frame)) / float(shot.last_frame - shot.first_frame);
  const float a = shot.light.turn_deg * kDeg * u;
  return glm::normalize(glm::vec3(std::cos(a) * d.x + std::sin(a) * d.z, d.y,
                                  -std::sin(a) * d.x + std::cos(a) * d.z));
}

}  // namespace emaki::scene
