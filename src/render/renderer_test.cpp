// ShotRenderer: clips, textures, looping, frame ranges and thread-count independence.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "core/error.h"
#include "core/parallel.h"
#include "io/gltf_loader.h"
#include "render/passes.h"

namespace emaki::render {
namespace {

const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";

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

}  // namespace
}  // namespace emaki::render
