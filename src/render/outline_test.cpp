// The outline pass: lines along the silhouette, none with a zero width.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "io/gltf_loader.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::render {
namespace {

const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";

// Pixels carrying a line, and of those how many lie within 3 pixels of the object.
struct Lines {
  int total = 0, near_object = 0;
};

Lines lines_of(const Image<float>& f) {
  Lines l;
  for (int y = 1; y + 1 < f.height(); ++y)
    for (int x = 1; x + 1 < f.width(); ++x) {
      if (f(x, y, kOutline) <= 0.0f) continue;
      ++l.total;
      bool near = false;
      for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
          const int sx = std::clamp(x + dx, 0, f.width() - 1);
          const int sy = std::clamp(y + dy, 0, f.height() - 1);
          near = near || f(sx, sy, kObjectId) >= 2.0f;
        }
      l.near_object += near;
    }
  return l;
}

TEST(Outline, LinesFollowTheSilhouetteAndAZeroWidthDrawsNone) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  scene::ShotSpec shot;
  shot.ground.enabled = false;
  RenderOptions options;
  options.width = 160;
  options.height = 90;
  const Lines drawn = lines_of(ShotRenderer(s, shot, options).render(0));
  EXPECT_GT(drawn.total, 50);
  EXPECT_EQ(drawn.near_object, drawn.total);
  options.outline_width = 0.0f;
  EXPECT_EQ(lines_of(ShotRenderer(s, shot, options).render(0)).total, 0);
}

}  // namespace
}  // namespace emaki::render
