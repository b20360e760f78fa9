#include "exemplar/reference_sphere.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::exemplar {
namespace {

constexpr double kPi = std::numbers::pi;

struct Rendered {
  Image<float> frame;
  scene::ViewCamera camera;
};

Rendered render_reference(const ReferenceSpec& spec, int aa) {
  static const scene::Scene sphere = sphere_scene();
  render::RenderOptions options;
  options.width = spec.width;
  options.height = spec.height;
  options.aa = aa;
  const render::ShotRenderer renderer(sphere, reference_shot(spec), options);
  return {renderer.render(0), renderer.camera(0.0f)};
}

// The normal pass against the exact normals of the sphere the camera looks at: the pixel
// centre's ray is intersected with the analytic unit sphere (not the mesh), in camera space.
TEST(ReferenceSphere, NormalPassMatchesAnalyticNormals) {
  ReferenceSpec spec;
  spec.width = 320;
  spec.height = 240;
  const Rendered r = render_reference(spec, 2);
  const glm::vec3 circle = sphere_circle(spec);
  const scene::ViewCamera& cam = r.camera;
  const glm::vec3 centre = glm::vec3(cam.view * glm::vec4(0, 1, 0, 1));
  const float aspect = float(spec.width) / spec.height;
  double sum = 0.0, worst = 0.0;
  int n = 0;
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const float* p = r.frame.at(x, y);
      // Covered pixels away from the antialiased rim (2 px).
      if (p[render::kAlpha] < 1.0f || p[render::kObjectId] != 2.0f) continue;
      if (std::hypot(x + 0.5f - circle.x, y + 0.5f - circle.y) > circle.z - 2.0f) continue;
      const float nx = (x + 0.5f) / spec.width * 2 - 1 - cam.shift.x;
      const float ny = 1 - (y + 0.5f) / spec.height * 2 - cam.shift.y;
      const glm::vec3 d =
          glm::normalize(glm::vec3(nx * cam.tan_half_fov * aspect, ny * cam.tan_half_fov, -1.0f));
      const float b = glm::dot(d, centre);
      const float disc = b * b - (glm::dot(centre, centre) - 1.0f);
      ASSERT_GT(disc, 0.0f) << "pixel " << x << "," << y << " misses the analytic sphere";
      const glm::vec3 hit = (b - std::sqrt(disc)) * d;
      const glm::vec3 exact = glm::normalize(hit - centre);
      const glm::vec3 pass(p[render::kNormal], p[render::kNormal + 1], p[render::kNormal + 2]);
      const double angle =
          std::acos(std::clamp(double(glm::dot(exact, glm::normalize(pass))), -1.0, 1.0)) * 180 /
          kPi;
      sum += angle;
      worst = std::max(worst, angle);
      ++n;
    }
  ASSERT_GT(n, 1000);
  const double mean = sum / n;
  std::printf("normal pass vs analytic sphere: mean %.4f deg, max %.4f deg over %d pixels\n", mean,
              worst, n);
  EXPECT_LT(mean, 1.0);
}

// Fitting: the sphere's coverage lands on the requested centre and radius, even off-centre.
TEST(ReferenceSphere, FitPutsTheSphereOnTheRequestedCircle) {
  ReferenceSpec spec;
  spec.width = 300;
  spec.height = 228;
  spec.center = {190.0f, 100.0f};
  spec.radius = 58.0f;
  spec.ground = false;
  const Rendered r = render_reference(spec, 3);
  double area = 0, sx = 0, sy = 0;
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const float a = r.frame(x, y, render::kAlpha);
      area += a, sx += a * (x + 0.5), sy += a * (y + 0.5);
    }
  EXPECT_NEAR(sx / area, 190.0, 0.25);
  EXPECT_NEAR(sy / area, 100.0, 0.25);
  EXPECT_NEAR(std::sqrt(area / kPi), 58.0, 0.25);
}

TEST(ReferenceSphere, HorizonRowSetsTheElevation) {
  ReferenceSpec spec;
  spec.width = 200;
  spec.height = 150;
  spec.horizon_row = 40.0f;
  const scene::ShotSpec shot = reference_shot(spec);
  // The camera sits above the horizon (looking down) and the horizon lands on row 40.
  const glm::vec3 eye = shot.camera.position;
  EXPECT_GT(eye.y, 1.0f);
  const Rendered r = render_reference(spec, 1);
  // Column 5 (far from the sphere): ground below the horizon row, background above it.
  EXPECT_EQ(r.frame(5, 36, render::kObjectId), 0.0f);
  EXPECT_EQ(r.frame(5, 44, render::kObjectId), 1.0f);
}

// The ground is a huge quad clipped by the near plane and the guard band on both of its
// triangles; the pieces must meet without cracks (a crack shows as alpha < 1 on open ground).
TEST(ReferenceSphere, GroundHasNoCracks) {
  for (float elevation : {15.0f, 10.0f, 30.0f}) {
    ReferenceSpec spec;
    spec.width = 300;
    spec.height = 225;
    spec.elevation_deg = elevation;
    const Rendered r = render_reference(spec, 2);
    int holes = 0;
    for (int y = spec.height / 2; y < spec.height; ++y)
      for (int x = 0; x < spec.width; ++x)
        holes += r.frame(x, y, render::kAlpha) < 1.0f && r.frame(x, y, render::kObjectId) != 2.0f;
    EXPECT_EQ(holes, 0) << "elevation " << elevation;
  }
}

TEST(ReferenceSphere, PaintTemplateIsGreyAndMarksTheContour) {
  ReferenceSpec spec;
  spec.width = 160;
  spec.height = 120;
  const Rendered r = render_reference(spec, 2);
  const Image<float> t = paint_template(r.frame.cview());
  ASSERT_EQ(t.channels(), 3);
  const glm::vec3 c = sphere_circle(spec);
  // Grey everywhere; the rim darker than the sphere just inside it.
  for (int y = 0; y < t.height(); ++y)
    for (int x = 0; x < t.width(); ++x) EXPECT_EQ(t(x, y, 0), t(x, y, 2));
  const int rim_x = int(c.x + c.z), cy = int(c.y);
  float rim = 1.0f;
  for (int x = rim_x - 2; x <= rim_x + 1; ++x) rim = std::min(rim, t(x, cy, 0));
  EXPECT_LT(rim, t(rim_x + 4, cy, 0));
}

}  // namespace
}  // namespace emaki::exemplar
