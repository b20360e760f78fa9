#include "exemplar/reference_sphere.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"
#include "render/passes.h"

namespace emaki::exemplar {

namespace {
constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kDeg = kPi / 180.0f;
}  // namespace

scene::Scene sphere_scene(int rings) {
  rings = std::max(rings, 4);
  const int segments = 2 * rings;
  scene::Primitive p;
  for (int r = 0; r <= rings; ++r) {
    const float theta = kPi * r / rings;  // from the top
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2.0f * kPi * s / segments;
      const glm::vec3 n(std::sin(theta) * std::sin(phi), std::cos(theta),
                        std::sin(theta) * std::cos(phi));
      p.positions.push_back(n + glm::vec3(0.0f, 1.0f, 0.0f));
      p.normals.push_back(n);
      p.uvs.push_back({float(s) / segments, float(r) / rings});
    }
  }
  const uint32_t row = uint32_t(segments + 1);
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = r * row + s, b = a + 1, c = a + row, d = c + 1;
      if (r > 0) p.indices.insert(p.indices.end(), {a, c, b});
      if (r + 1 < rings) p.indices.insert(p.indices.end(), {b, c, d});
    }
  scene::Scene sc;
  scene::Mesh mesh;
  mesh.name = "reference_sphere";
  mesh.primitives.push_back(std::move(p));
  sc.meshes.push_back(std::move(mesh));
  scene::Material grey;
  grey.name = "reference_grey";
  grey.base_color = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
  sc.materials.push_back(grey);
  sc.meshes[0].primitives[0].material = 0;
  scene::Node node;
  node.name = "sphere";
  node.mesh = 0;
  sc.nodes.push_back(node);
  sc.roots.push_back(0);
  return sc;
}

glm::vec3 sphere_circle(const ReferenceSpec& spec) {
  const float cx = spec.center.x >= 0.0f ? spec.center.x : 0.5f * spec.width;
  const float cy = spec.center.y >= 0.0f ? spec.center.y : 0.5f * spec.height;
  const float r = spec.radius > 0.0f ? spec.radius : 0.3f * spec.height;
  return {cx, cy, r};
}

scene::ShotSpec reference_shot(const ReferenceSpec& spec) {
  const glm::vec3 circle = sphere_circle(spec);
  const float tan_half = std::tan(0.5f * std::clamp(spec.fov_deg, 1.0f, 120.0f) * kDeg);
  const float focal = 0.5f * spec.height / tan_half;  // pixels
  // On the optical axis a sphere's outline is a circle of angular radius asin(1 / distance).
  const float alpha = std::atan(circle.z / focal);
  if (!(alpha > 0.0f) || alpha > 80.0f * kDeg)
    throw Error(
        Error::Field{"sphere"},
        fmt::format("radius {} px does not fit a {} degree field of view", circle.z, spec.fov_deg));
  const float distance = 1.0f / std::sin(alpha);

  scene::ShotSpec shot;
  scene::CameraSpec& cam = shot.camera;
  cam.mode = scene::CameraSpec::Mode::kLookAt;
  cam.fov_deg = spec.fov_deg;
  cam.shift = {(circle.x - 0.5f * spec.width) / (0.5f * spec.width),
               -(circle.y - 0.5f * spec.height) / (0.5f * spec.height)};
  float elevation = spec.elevation_deg * kDeg;
  if (!std::isnan(spec.horizon_row)) {
    // The horizon is `elevation` above the optical axis: y_ndc = tan(elevation) / tan_half + shift.
    const float y_ndc = 1.0f - 2.0f * spec.horizon_row / spec.height;
    elevation = std::atan((y_ndc - cam.shift.y) * tan_half);
  }
  if (std::abs(elevation) > 80.0f * kDeg)
    throw Error(Error::Field{"horizon"},
                "puts the camera more than 80 degrees above or below the horizon");
  cam.target = glm::vec3(0.0f, 1.0f, 0.0f);
  cam.has_target = true;
  cam.position = cam.target + distance * glm::vec3(0.0f, std::sin(elevation), std::cos(elevation));
  shot.light = spec.light;
  shot.ground.enabled = spec.ground;
  shot.ground.auto_height = false;
  shot.ground.height = 0.0f;
  shot.ground.size = 1e4f;  // its far edge within a pixel of the true horizon
  shot.ground.color = spec.ground_color;
  shot.background = spec.background;
  shot.first_frame = shot.last_frame = 0;
  return shot;
}

Image<float> paint_template(ImageView<const float> passes) {
  using namespace render;
  Image<float> out(passes.width, passes.height, 3);
  auto encode = [](float c) {
    c = std::clamp(c, 0.0f, 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  };
  for (int y = 0; y < passes.height; ++y)
    for (int x = 0; x < passes.width; ++x) {
      const float* p = passes.at(x, y);
      const float alpha = p[kAlpha];
      const float background = 0.85f;
      // Which surface a pixel shows: its dominant id, or (an edge pixel where the background
      // dominates) the covered samples' albedo, the sphere's being the darker grey.
      const int id = int(std::lround(p[kObjectId]));
      const bool sphere = id >= 2 || (id == 0 && p[kAlbedo] < 0.65f);
      float v;
      if (sphere) {
        // Soft light: a lifted Lambert so the dark side stays readable for painting.
        const float lit = 0.30f + 0.50f * std::pow(std::max(p[kDiffuse], 0.0f), 0.8f);
        v = lit * (1.0f - 0.15f * p[kShadow]);
      } else {
        v = 0.72f * (1.0f - 0.22f * p[kShadow]);  // ground: the cast shadow faintly darker
      }
      v = alpha * v + (1.0f - alpha) * background;
      v *= 1.0f - 0.35f * std::clamp(p[kOutline], 0.0f, 1.0f);  // faint contour
      const float e = encode(v);
      for (int c = 0; c < 3; ++c) out(x, y, c) = e;
    }
  return out;
}

}  // namespace emaki::exemplar
