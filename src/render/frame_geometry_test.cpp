// One frame's posed geometry as the passes show it: following the motion pass from a pixel to
// the previous frame lands on the same surface point (its positions agree).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "io/gltf_loader.h"
#include "render/passes.h"
#include "render/renderer.h"

namespace emaki::render {
namespace {

const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";

// Bilinear sample of channels [first, first + 3) at pixel coordinates (x right, y down, centres
// at +0.5); false where any of the four pixels is not fully covered, has another object id or
// carries a line (lines mark silhouettes and depth jumps, where a point can be hidden in one
// frame and seen in the other).
bool sample3(const Image<float>& f, float px, float py, int first, float object, glm::vec3& out) {
  const float x = px - 0.5f, y = py - 0.5f;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= f.width() || y0 + 1 >= f.height()) return false;
  const float fx = x - x0, fy = y - y0;
  glm::vec3 v(0.0f);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const float* p = f.at(x0 + i, y0 + j);
      if (p[kAlpha] < 1.0f || p[kObjectId] != object || p[kOutline] > 0.0f) return false;
      const float w = (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
      v += w * glm::vec3(p[first], p[first + 1], p[first + 2]);
    }
  out = v;
  return true;
}

struct Agreement {
  double mean = 0, p95 = 0;
  int pixels = 0, candidates = 0;
};

// Follows `motion` from each pixel of frame t to frame t-1 and compares channel `first` there.
Agreement follow_motion(const Image<float>& cur, const Image<float>& prev, int first,
                        float min_object) {
  std::vector<double> errors;
  Agreement a;
  for (int y = 0; y < cur.height(); ++y)
    for (int x = 0; x < cur.width(); ++x) {
      const float* p = cur.at(x, y);
      if (p[kAlpha] < 1.0f || p[kObjectId] < min_object || p[kOutline] > 0.0f) continue;
      ++a.candidates;
      glm::vec3 there;
      if (!sample3(prev, x + 0.5f + p[kMotion], y + 0.5f + p[kMotion + 1], first, p[kObjectId],
                   there))
        continue;
      errors.push_back(glm::length(there - glm::vec3(p[first], p[first + 1], p[first + 2])));
    }
  a.pixels = int(errors.size());
  if (errors.empty()) return a;
  double sum = 0;
  for (double e : errors) sum += e;
  a.mean = sum / errors.size();
  std::sort(errors.begin(), errors.end());
  a.p95 = errors[std::size_t(0.95 * (errors.size() - 1))];
  return a;
}

// A static prop under an orbiting, dollying camera: the same surface point keeps its
// normalised position, so following the motion vectors must land on the same values.
TEST(Render, StaticObjectMovingCameraPositionsFollowMotion) {
  const scene::Scene s = io::load_gltf(kScenes + "cakeBirthday.glb");
  scene::ShotSpec shot;
  shot.first_frame = 0;
  shot.last_frame = 10;
  shot.camera.orbit_deg = 40.0f;
  shot.camera.dolly = 0.8f;
  shot.camera.elevation_deg = 25.0f;
  RenderOptions options;
  options.width = 320;
  options.height = 180;
  const ShotRenderer r(s, shot, options);
  const Image<float> prev = r.render(4), cur = r.render(5);
  const Agreement a = follow_motion(cur, prev, kPositionNorm, 1.0f);
  std::printf(
      "static object, moving camera: position_norm error mean %.5f, p95 %.5f (box units) "
      "over %d of %d covered pixels\n",
      a.mean, a.p95, a.pixels, a.candidates);
  ASSERT_GT(a.pixels, 0.5 * a.candidates);
  EXPECT_LT(a.mean, 0.005);
  EXPECT_LT(a.p95, 0.005);
  // The camera did move: the motion field is not zero.
  double motion = 0;
  for (int y = 0; y < cur.height(); ++y)
    for (int x = 0; x < cur.width(); ++x)
      motion = std::max<double>(motion, std::abs(cur(x, y, kMotion)));
  EXPECT_GT(motion, 2.0);
}

// The walking Fox: rest_position follows the skin, world position does not.
TEST(Render, FoxWalkRestPositionFollowsMotion) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  scene::ShotSpec shot;
  shot.clip = "Walk";
  shot.first_frame = 0;
  shot.last_frame = 16;
  RenderOptions options;
  options.width = 480;
  options.height = 270;
  const ShotRenderer r(s, shot, options);
  const Image<float> prev = r.render(7), cur = r.render(8);
  const Agreement rest = follow_motion(cur, prev, kRestPosition, 2.0f);
  const Agreement pos = follow_motion(cur, prev, kPositionNorm, 2.0f);
  std::printf(
      "Fox Walk frame 8 -> 7: rest_position error mean %.5f p95 %.5f; position_norm error "
      "mean %.5f p95 %.5f (box units) over %d of %d fox pixels\n",
      rest.mean, rest.p95, pos.mean, pos.p95, rest.pixels, rest.candidates);
  ASSERT_GT(rest.pixels, 0.5 * rest.candidates);
  EXPECT_LT(rest.mean, 0.005);
  EXPECT_LT(rest.p95, 0.005);
  // World position moves with the walk: comparing it along the motion does not agree.
  EXPECT_GT(pos.mean, 2.0 * rest.mean);
}

}  // namespace
}  // namespace emaki::render
