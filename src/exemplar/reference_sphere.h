// The MatCap-like reference scene: a unit sphere standing on a ground plane under the key light,
// rendered with the same passes as a shot, and the paint template an artist paints over. The
// camera looks at the sphere's centre (so it projects to a circle) with a lens shift that puts
// that circle at any centre and radius in the image: the same construction places the passes
// over a sphere that was painted before any of this existed (fitting).
#pragma once

#include <cmath>
#include <glm/glm.hpp>

#include "core/image.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "scene/staging.h"

namespace emaki::exemplar {

// The reference camera's default elevation, degrees above the horizon: the one default of
// `emaki template --elevation`, emaki.template(elevation=), a shot's exemplars.NAME.elevation
// and the Blender exporter's --reference --elevation. python/tests/test_defaults.py checks that
// every front end (and the docs) shows this value.
inline constexpr float kDefaultReferenceElevationDeg = 10.0f;

struct ReferenceSpec {
  int width = 1024;                // pixels
  int height = 768;                // pixels
  glm::vec2 center{-1.0f, -1.0f};  // sphere centre in pixels (x right, y down); <0: image centre
  float radius = 0.0f;             // sphere radius in pixels; 0: 30 % of the height
  float elevation_deg = kDefaultReferenceElevationDeg;  // above the horizon, [-80, 80]
  float horizon_row = NAN;  // if set: elevation chosen so the horizon sits on this row
  float fov_deg = 30.0f;    // vertical field of view, [1, 120]
  scene::LightSpec light;   // camera-relative by default, as in a shot
  bool ground = true;
  glm::vec3 ground_color{0.8f};
  glm::vec3 background{0.0f};
};

// A UV sphere of radius 1 centred at (0, 1, 0) (resting on y = 0), with exact normals.
scene::Scene sphere_scene(int rings = 128);

// The shot that frames the sphere as `spec` asks (a single frame, 0). Throws emaki::Error naming
// the field (Error::Field) for a sphere that does not fit the camera ("sphere") or a horizon
// that cannot be reached ("horizon").
scene::ShotSpec reference_shot(const ReferenceSpec& spec);

// The sphere's centre and radius in pixels for `spec` (defaults resolved).
glm::vec3 sphere_circle(const ReferenceSpec& spec);

// The paint template (RGB, sRGB-encoded, [0, 1]) made from a reference frame's passes: a soft-lit
// grey sphere on a lighter ground, its contour and cast shadow faintly marked.
Image<float> paint_template(ImageView<const float> passes);

}  // namespace emaki::exemplar
