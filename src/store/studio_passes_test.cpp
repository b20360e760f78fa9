#include "store/studio_passes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "render/passes.h"

namespace emaki::io {
namespace {

using namespace render;

// A pinhole camera looking from `eye` at `target` (+Y up), focal length in pixels, principal
// point (cx, cy) (pixels, y down).
struct TestCamera {
  glm::vec3 eye, right, up, back;
  float focal, cx, cy;
  TestCamera(glm::vec3 e, glm::vec3 target, float f, float px, float py)
      : eye(e), focal(f), cx(px), cy(py) {
    back = glm::normalize(e - target);
    right = glm::normalize(glm::cross(glm::vec3(0, 1, 0), back));
    up = glm::cross(back, right);
  }
  // The world point at pixel (u, v) (y down) and distance `depth` along the axis.
  glm::vec3 unproject(float u, float v, float depth) const {
    const float x = (u - cx) / focal * depth, y = -(v - cy) / focal * depth;
    return eye + x * right + y * up - depth * back;
  }
};

TEST(FitCameraAxes, RecoversAPerspectiveCameraWithLensShift) {
  const TestCamera cam({4.0f, 2.5f, 6.0f}, {0.0f, 0.5f, 0.0f}, 180.0f, 91.0f, 40.0f);
  std::vector<glm::vec3> world;
  std::vector<glm::vec2> pixel;
  for (int v = 0; v < 90; v += 6)
    for (int u = 0; u < 160; u += 6) {
      const float depth = 6.0f + 1.5f * std::sin(0.1f * u) * std::cos(0.13f * v);
      world.push_back(cam.unproject(u + 0.5f, v + 0.5f, depth));
      pixel.push_back({u + 0.5f, v + 0.5f});
    }
  const CameraAxes axes = fit_camera_axes(world, pixel, "f.exr");
  EXPECT_GT(glm::dot(axes.right, cam.right), 0.99999f);
  EXPECT_GT(glm::dot(axes.up, cam.up), 0.99999f);
  EXPECT_GT(glm::dot(axes.back, cam.back), 0.99999f);
}

TEST(FitCameraAxes, RecoversAnOrthographicCamera) {
  const TestCamera cam({-3.0f, 4.0f, 5.0f}, {0.0f, 0.0f, 0.0f}, 1.0f, 80.0f, 45.0f);
  std::vector<glm::vec3> world;
  std::vector<glm::vec2> pixel;
  const float scale = 20.0f;  // pixels per unit
  for (int v = 0; v < 90; v += 5)
    for (int u = 0; u < 160; u += 5) {
      const float x = (u - 80.0f) / scale, y = -(v - 45.0f) / scale;
      const float depth = 7.0f + std::sin(0.2f * u + 0.1f * v);
      world.push_back(cam.eye + x * cam.right + y * cam.up - depth * cam.back);
      pixel.push_back({float(u), float(v)});
    }
  const CameraAxes axes = fit_camera_axes(world, pixel, "f.exr");
  EXPECT_GT(glm::dot(axes.right, cam.right), 0.9999f);
  EXPECT_GT(glm::dot(axes.up, cam.up), 0.9999f);
  EXPECT_GT(glm::dot(axes.back, cam.back), 0.9999f);
}

TEST(FitCameraAxes, RefusesPointsOnOnePlaneNamingTheFile) {
  const TestCamera cam({0.0f, 3.0f, 6.0f}, {0.0f, 0.0f, 0.0f}, 150.0f, 80.0f, 45.0f);
  std::vector<glm::vec3> world;
  std::vector<glm::vec2> pixel;
  for (int v = 50; v < 90; v += 4)
    for (int u = 0; u < 160; u += 4) {
      // Where the pixel's ray meets the ground y = 0.
      const glm::vec3 d = cam.unproject(u + 0.5f, v + 0.5f, 1.0f) - cam.eye;
      world.push_back(cam.eye + d * (-cam.eye.y / d.y));
      pixel.push_back({u + 0.5f, v + 0.5f});
    }
  try {
    fit_camera_axes(world, pixel, "renders/frame_0001.exr");
    FAIL() << "a plane does not determine a camera";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "renders/frame_0001.exr");
    EXPECT_NE(std::string(e.what()).find("one plane"), std::string::npos) << e.what();
  }
}

// A raw Blender frame of a bumpy surface seen by `cam`: Z-up world positions and normals,
// premultiplied by alpha, Blender's ids and Vector.
Image<float> raw_frame(const TestCamera& cam, float alpha_at_edge) {
  const int w = 64, h = 40;
  Image<float> raw(w, h, kBlenderChannelCount);
  auto zup = [](glm::vec3 p) { return glm::vec3(p.x, -p.z, p.y); };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* r = raw.at(x, y);
      if (x == 0) continue;  // background column
      const float a = x == 1 ? alpha_at_edge : 1.0f;
      const float depth = 5.0f + 0.8f * std::sin(0.3f * x) * std::cos(0.2f * y);
      const glm::vec3 p = zup(cam.unproject(x + 0.5f, y + 0.5f, depth));
      const glm::vec3 n = zup(glm::normalize(glm::vec3(0.0f, 1.0f, 0.2f)));
      for (int c = 0; c < 3; ++c) {
        r[0 + c] = a * n[c];
        r[3 + c] = a * p[c];
        r[7 + c] = a * 0.5f;              // DiffDir
        r[10 + c] = a * 0.25f * (c + 1);  // DiffCol
      }
      r[6] = depth;
      r[13] = y < 20 ? 0.0f : 1.0f;  // IndexOB: Blender's default 0, and the ground
      r[14] = 3.0f;
      r[15] = a * 2.0f;  // Vector.X
      r[16] = a * 3.0f;  // Vector.Y (up)
      r[17] = a;
    }
  return raw;
}

TEST(BlenderToEmaki, ConvertsBlendersConventions) {
  const TestCamera cam({1.0f, 2.0f, 6.0f}, {0.0f, 0.0f, 0.0f}, 70.0f, 32.0f, 20.0f);
  const Image<float> raw = raw_frame(cam, 0.5f);
  const Image<float> out = blender_to_emaki(raw.cview(), Cube{}, "f.exr");
  ASSERT_EQ(out.channels(), kChannelCount);
  // Background stays zero but for the outline, drawn on both sides of the silhouette.
  for (int c = 0; c < kChannelCount; ++c) {
    if (c != kOutline) {
      EXPECT_EQ(out(0, 5, c), 0.0f) << c;
    }
  }
  EXPECT_EQ(out(0, 5, kOutline), 1.0f);
  const glm::vec3 n_world = glm::normalize(glm::vec3(0.0f, 1.0f, 0.2f));
  const glm::vec3 n_cam(glm::dot(n_world, cam.right), glm::dot(n_world, cam.up),
                        glm::dot(n_world, cam.back));
  for (int x : {1, 30}) {  // the half-covered edge pixel is unpremultiplied
    const float* o = out.at(x, 10);
    EXPECT_NEAR(o[kNormal], n_cam.x, 1e-3f);
    EXPECT_NEAR(o[kNormal + 1], n_cam.y, 1e-3f);
    EXPECT_NEAR(o[kNormal + 2], n_cam.z, 1e-3f);
    const glm::vec3 p =
        cam.unproject(x + 0.5f, 10.5f, 5.0f + 0.8f * std::sin(0.3f * x) * std::cos(0.2f * 10));
    EXPECT_NEAR(o[kPosition], p.x, 1e-4f);
    EXPECT_NEAR(o[kPosition + 1], p.y, 1e-4f);  // +Y up again
    EXPECT_NEAR(o[kPosition + 2], p.z, 1e-4f);
    EXPECT_NEAR(o[kAlbedo + 2], 0.75f, 1e-5f);
    EXPECT_NEAR(o[kMotion], 2.0f, 1e-5f);       // x right, as Blender's
    EXPECT_NEAR(o[kMotion + 1], -3.0f, 1e-5f);  // y down
    EXPECT_EQ(o[kObjectId], 2.0f);              // Blender's default index 0: an object
    EXPECT_EQ(o[kMaterialId], 3.0f);
  }
  EXPECT_NEAR(out(1, 10, kAlpha), 0.5f, 1e-6f);
  EXPECT_EQ(out(30, 30, kObjectId), 1.0f);  // index 1: the ground
  // The id change between rows 19 and 20 is a line; the ground against the background is not.
  EXPECT_EQ(out(30, 19, kOutline), 1.0f);
  EXPECT_EQ(out(30, 20, kOutline), 1.0f);
  EXPECT_EQ(out(1, 30, kOutline), 0.0f);
}

TEST(BlenderToEmaki, DividesTheLightStrengthOutOfDiffuse) {
  // DiffDir = 2 x N.L (a sun of strength 2): diffuse comes out as N.L, no cast shadow.
  const TestCamera cam({0.0f, 1.0f, 6.0f}, {0.0f, 0.0f, 0.0f}, 70.0f, 32.0f, 20.0f);
  Image<float> raw = raw_frame(cam, 1.0f);
  const glm::vec3 light_cam = glm::normalize(glm::vec3(0.3f, 0.8f, 0.5f));
  for (int y = 0; y < raw.height(); ++y)
    for (int x = 1; x < raw.width(); ++x) {
      float* r = raw.at(x, y);
      // Normals spread over the hemisphere so the light is determined.
      const glm::vec3 n_cam =
          glm::normalize(glm::vec3(std::sin(0.1f * x), 0.6f + 0.4f * std::cos(0.15f * y), 0.7f));
      const glm::vec3 n_world = n_cam.x * cam.right + n_cam.y * cam.up + n_cam.z * cam.back;
      const glm::vec3 n = {n_world.x, -n_world.z, n_world.y};
      const float d = 2.0f * std::max(0.0f, glm::dot(n_cam, light_cam));
      for (int c = 0; c < 3; ++c) r[c] = n[c], r[7 + c] = d;
    }
  const Image<float> out = blender_to_emaki(raw.cview(), Cube{}, "f.exr");
  for (int x : {10, 40})
    for (int y : {5, 35}) {
      const glm::vec3 n(out(x, y, kNormal), out(x, y, kNormal + 1), out(x, y, kNormal + 2));
      EXPECT_NEAR(out(x, y, kDiffuse), std::max(0.0f, glm::dot(n, light_cam)), 2e-3f);
      EXPECT_NEAR(out(x, y, kShadow), 0.0f, 2e-3f);
    }
}

TEST(ApplyConventions, ConvertsWorldNormalsZUpAndPremultipliedValues) {
  const TestCamera cam({2.0f, 3.0f, 5.0f}, {0.0f, 0.5f, 0.0f}, 60.0f, 24.0f, 16.0f);
  Image<float> frame(48, 32, kChannelCount);
  const glm::vec3 n_world = glm::normalize(glm::vec3(0.2f, 1.0f, 0.1f));
  auto zup = [](glm::vec3 p) { return glm::vec3(p.x, -p.z, p.y); };
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 48; ++x) {
      float* o = frame.at(x, y);
      const float a = x == 5 ? 0.25f : 1.0f;
      const glm::vec3 p = zup(cam.unproject(x + 0.5f, y + 0.5f, 4.0f + std::sin(0.3f * x + y)));
      const glm::vec3 n = zup(n_world);
      for (int c = 0; c < 3; ++c) o[kPosition + c] = a * p[c], o[kNormal + c] = a * n[c];
      o[kDiffuse] = a * 0.5f;
      o[kObjectId] = 2.0f;
      o[kAlpha] = a;
    }
  apply_conventions(frame, {true, true, true}, "f.exr");
  for (int x : {5, 20}) {
    const float* o = frame.at(x, 9);
    EXPECT_NEAR(o[kNormal], glm::dot(n_world, cam.right), 1e-3f);
    EXPECT_NEAR(o[kNormal + 1], glm::dot(n_world, cam.up), 1e-3f);
    EXPECT_NEAR(o[kNormal + 2], glm::dot(n_world, cam.back), 1e-3f);
    const glm::vec3 p = cam.unproject(x + 0.5f, 9.5f, 4.0f + std::sin(0.3f * x + 9));
    EXPECT_NEAR(o[kPosition + 1], p.y, 1e-4f);
    EXPECT_NEAR(o[kPosition + 2], p.z, 1e-4f);
    EXPECT_NEAR(o[kDiffuse], 0.5f, 1e-6f);
    EXPECT_EQ(o[kObjectId], 2.0f);  // ids are not divided
  }
  EXPECT_EQ(frame(5, 9, kAlpha), 0.25f);
}

TEST(BlenderToEmaki, ChannelNamesFollowTheViewLayer) {
  const std::vector<std::string> c = blender_channels("RenderLayer");
  ASSERT_EQ(int(c.size()), kBlenderChannelCount);
  EXPECT_EQ(c.front(), "RenderLayer.Normal.X");
  EXPECT_EQ(c.back(), "RenderLayer.Combined.A");
}

}  // namespace
}  // namespace emaki::io
