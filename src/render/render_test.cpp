#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "io/gltf_loader.h"
#include "render/passes.h"
#include "render/raster.h"
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

TEST(Render, FoxRendersEveryClip) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  ASSERT_EQ(s.animations.size(), 3u);
  for (const scene::Animation& a : s.animations) {
    scene::ShotSpec shot;
    shot.clip = a.name;
    shot.last_frame = int(std::floor((a.end - a.start) * shot.fps));
    RenderOptions options;
    options.width = 160;
    options.height = 90;
    const ShotRenderer r(s, shot, options);
    for (int f : {0, shot.last_frame / 2, shot.last_frame}) {
      const Image<float> frame = r.render(f);
      EXPECT_GT(object_coverage(frame.cview()), 0.01f) << a.name << " frame " << f;
    }
  }
}

TEST(Render, FoxAlbedoComesFromItsTexture) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  ASSERT_EQ(s.textures.size(), 1u);
  scene::ShotSpec shot;
  RenderOptions options;
  options.width = 160;
  options.height = 90;
  const Image<float> f = ShotRenderer(s, shot, options).render(0);
  // The texture is orange with white and dark patches: the fox's albedo must vary.
  float lo = 1, hi = 0;
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x)
      if (f(x, y, kObjectId) >= 2.0f && f(x, y, kAlpha) == 1.0f)
        lo = std::min(lo, f(x, y, kAlbedo)), hi = std::max(hi, f(x, y, kAlbedo));
  EXPECT_GT(hi - lo, 0.3f);
}

TEST(Render, ResultDoesNotDependOnThreadCount) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  scene::ShotSpec shot;
  shot.last_frame = 3;
  RenderOptions options;
  options.width = 200;
  options.height = 120;
  const ShotRenderer r(s, shot, options);
  const auto render_with = [&](int threads) {
    const ScopedThreadCount count(threads);
    return r.render(2);
  };
  const Image<float> a = render_with(1);
  const Image<float> b = render_with(2);
  ASSERT_EQ(a.bytes(), b.bytes());
  EXPECT_EQ(std::memcmp(a.row(0), b.row(0), a.bytes()), 0);
}

TEST(Render, FrameRangePastTheClipIsAnError) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  scene::ShotSpec shot;
  shot.clip = "Run";
  shot.last_frame = 1000;
  EXPECT_THROW({ const ShotRenderer r(s, shot, RenderOptions{}); }, emaki::Error);
  shot.clip = "Fly";
  shot.last_frame = 0;
  EXPECT_THROW({ const ShotRenderer r(s, shot, RenderOptions{}); }, emaki::Error);
}

// A looping clip: frames run past the clip's end, and a frame one cycle later is the same pose.
TEST(Render, LoopingClipRepeatsEveryCycle) {
  const scene::Scene s = io::load_gltf(kScenes + "Fox.glb");
  scene::ShotSpec shot;
  shot.clip = "Walk";
  shot.last_frame = 47;
  EXPECT_THROW({ const ShotRenderer r(s, shot, RenderOptions{}); }, emaki::Error);
  shot.loop = true;
  RenderOptions options;
  options.width = 160;
  options.height = 90;
  const ShotRenderer r(s, shot, options);
  const scene::Animation& walk = s.animations[r.animation()];
  const float duration = walk.end - walk.start;
  const int cycle = int(std::lround(duration * shot.fps));
  ASSERT_NEAR(cycle / shot.fps, duration, 1e-3f) << "the Walk clip is a whole number of frames";
  for (int f : {0, 5, 16}) {
    EXPECT_NEAR(r.time_of(float(f + cycle)), r.time_of(float(f)), 1e-4f) << f;
    EXPECT_NEAR(r.time_of(float(f + 2 * cycle)), r.time_of(float(f)), 1e-4f) << f;
  }
  EXPECT_GE(r.time_of(-1.0f), walk.start);  // the motion pass of frame 0 looks back into the loop
  EXPECT_LE(r.time_of(float(shot.last_frame)), walk.end);
  // The camera does not move (no orbit/dolly), so a cycle later the passes are the same.
  const Image<float> a = r.render(5), b = r.render(5 + cycle);
  float worst = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c : {int(kNormal), kNormal + 1, kNormal + 2, int(kRestPosition), kRestPosition + 1})
        worst = std::max(worst, std::abs(a(x, y, c) - b(x, y, c)));
  EXPECT_LT(worst, 1e-3f);
  EXPECT_GT(object_coverage(b.cview()), 0.01f);
}

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

TEST(Passes, ChannelNamesMatchTheLayout) {
  const std::vector<std::string> names = channel_names();
  ASSERT_EQ(int(names.size()), kChannelCount);
  EXPECT_EQ(names[kNormal], "normal.X");
  EXPECT_EQ(names[kRestPosition + 2], "rest_position.Z");
  EXPECT_EQ(names[kMotion + 1], "motion.Y");
  EXPECT_EQ(names[kAlpha], "alpha.A");
}

}  // namespace
}  // namespace emaki::render
