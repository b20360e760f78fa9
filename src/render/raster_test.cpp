// The rasterizer: clipping against the near plane.
#include "render/raster.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace emaki::render {
namespace {

// A ground-like quad far larger than the view, crossing the near plane, split into two
// triangles: both are clipped, and the clipped pieces must still tile the view without cracks.
TEST(Raster, ClippedQuadLeavesNoCracks) {
  // Perspective camera at the origin looking down -Z at a plane y = -1 from z = +50 to -5000.
  auto clip = [](glm::vec3 p) {
    const float depth = -p.z;
    return ClipVertex{p.x / 0.4f, p.y / 0.3f, depth, depth};
  };
  const std::vector<ClipVertex> v = {clip({-3000, -1, 50}), clip({3000, -1, 50}),
                                     clip({3000, -1, -5000}), clip({-3000, -1, -5000})};
  const std::vector<uint32_t> idx = {0, 1, 2, 0, 2, 3};
  RasterOptions ro;
  ro.znear = 0.05f;
  VisibilityBuffer vb;
  vb.reset(320, 240, true);
  rasterize(v, idx, ro, vb);
  int holes = 0, covered = 0;
  for (int y = 0; y < vb.height; ++y)
    for (int x = 0; x < vb.width; ++x) {
      // Below the horizon (row 120) everything is ground.
      if (y < 122) continue;
      ++covered;
      if (vb.tri[vb.index(x, y)] < 0) ++holes;
    }
  EXPECT_GT(covered, 30000);
  EXPECT_EQ(holes, 0);
}

}  // namespace
}  // namespace emaki::render
