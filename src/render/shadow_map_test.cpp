// The key light's shadow map as the shadow pass shows it.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "io/gltf_loader.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::render {
namespace {

const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";

// A light that turns over the shot moves the cast shadow on the ground while the scene and the
// camera stand still; without the turn the shadow pass is the same at every frame.
TEST(Render, TurningLightMovesTheShadow) {
  const scene::Scene s = io::load_gltf(kScenes + "cakeBirthday.glb");
  scene::ShotSpec shot;
  shot.first_frame = 0;
  shot.last_frame = 10;
  shot.light.direction = glm::vec3(1.0f, 1.0f, 0.0f);
  shot.light.camera_relative = false;
  RenderOptions options;
  options.width = 160;
  options.height = 90;
  auto shadow_change = [&](float turn) {
    shot.light.turn_deg = turn;
    const ShotRenderer r(s, shot, options);
    const Image<float> a = r.render(0), b = r.render(10);
    double d = 0.0;
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) d += std::abs(a(x, y, kShadow) - b(x, y, kShadow));
    return d;
  };
  EXPECT_EQ(shadow_change(0.0f), 0.0);
  EXPECT_GT(shadow_change(90.0f), 50.0);  // pixels' worth of shadow moved
}

}  // namespace
}  // namespace emaki::render
