#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <numbers>
#include <string>

#include "io/gltf_loader.h"
#include "scene/staging.h"

namespace emaki::scene {
namespace {

const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";
constexpr float kPi = std::numbers::pi_v<float>;

void expect_near(const glm::vec3& a, const glm::vec3& b, float tol = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// SimpleSkin: joint 1 (node 2, at y = 1 under joint 0) turns about Z: 0 at t = 0, 45 deg
// (quaternion z = 0.383) at t = 0.5, 90 deg (z = 0.707) at t = 1. Both inverse bind matrices are
// translate(-0.5, -1, 0), so a vertex bound to joint 1 only lands at
// (0, 1, 0) + Rz(theta) * (p + (-0.5, -1, 0)).
TEST(SimpleSkin, JointAndVertexPosesFollowTheClip) {
  const Scene s = io::load_gltf(kScenes + "SimpleSkin.gltf");
  ASSERT_EQ(s.animations.size(), 1u);
  ASSERT_EQ(s.skins.size(), 1u);
  for (float t : {0.0f, 0.25f, 1.0f, 4.25f}) {
    // Hand-computed: linear keys every 0.5 s; slerp halfway between 0 and 45 deg is 22.5 deg;
    // t = 4.25 is halfway between -90 deg (4.0) and -90 deg (4.5).
    const float theta_deg = t == 0.0f ? 0.0f : t == 0.25f ? 22.5f : t == 1.0f ? 90.0f : -90.0f;
    const float theta = theta_deg * kPi / 180.0f;
    const Pose pose = evaluate_pose(s, 0, t);
    const glm::mat4 expected_joint =
        glm::translate(glm::mat4(1.0f), {0, 1, 0}) * glm::rotate(glm::mat4(1.0f), theta, {0, 0, 1});
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_NEAR(pose.world[2][c][r], expected_joint[c][r], 2e-3f) << "t=" << t;

    const PosedScene posed = pose_scene(s, 0, t);
    ASSERT_EQ(posed.primitives.size(), 1u);
    const auto& p = posed.primitives[0].world_positions;
    // Vertex 8 is (0, 2, 0) bound to joint 1 only; vertex 0 is (0, 0, 0) bound to joint 0 only.
    const glm::vec3 local(-0.5f, 1.0f, 0.0f);
    const glm::vec3 v8(std::cos(theta) * local.x - std::sin(theta) * local.y,
                       1.0f + std::sin(theta) * local.x + std::cos(theta) * local.y, 0.0f);
    expect_near(p[8], v8, 2e-3f);
    expect_near(p[0], {-0.5f, 0.0f, 0.0f});
    // Vertex 4 is (0, 1, 0) weighted half and half.
    const glm::vec3 v4 =
        0.5f * glm::vec3(-0.5f, 1.0f, 0.0f) +
        0.5f * (glm::vec3(0, 1, 0) + glm::vec3(glm::rotate(glm::mat4(1.0f), theta, {0, 0, 1}) *
                                               glm::vec4(-0.5f, 0.0f, 0.0f, 1.0f)));
    expect_near(p[4], v4, 2e-3f);
  }
}

// BoxAnimated: node 0 translates y 0 -> 2.52 over [0, 1.25], holds, back to 0 at 3.708; node 2
// (the box, under nodes 0 and 1) turns from identity to 180 deg about X over [1.25, 2.5].
TEST(BoxAnimated, NodesFollowTheClip) {
  const Scene s = io::load_gltf(kScenes + "BoxAnimated.gltf");
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_NEAR(s.animations[0].end, 3.70833f, 1e-4f);
  struct Case {
    float t, y, angle_deg;
  };
  for (const Case c :
       {Case{0.0f, 0.0f, 0.0f}, Case{0.625f, 1.26f, 0.0f}, Case{1.875f, 2.52f, 90.0f},
        Case{2.5f, 2.52f, 180.0f}, Case{3.1041650f, 1.26f, 180.0f}}) {
    const Pose pose = evaluate_pose(s, 0, c.t);
    expect_near(glm::vec3(pose.world[0][3]), {0.0f, c.y, 0.0f}, 1e-3f);
    // The box's world rotation angle about X (its direction is a sign convention of slerp on
    // antipodal-looking keys, so check the angle through the image of +Y).
    const glm::vec3 y_axis = glm::mat3(pose.world[2]) * glm::vec3(0, 1, 0);
    const float angle = std::acos(std::clamp(y_axis.y, -1.0f, 1.0f)) * 180.0f / kPi;
    EXPECT_NEAR(angle, c.angle_deg, 0.05f) << "t=" << c.t;
    EXPECT_NEAR(y_axis.x, 0.0f, 1e-5f);
    expect_near(glm::vec3(pose.world[2][3]), {0.0f, c.y, 0.0f}, 1e-3f);
  }
}

AnimSampler make_sampler(Interpolation interp, std::vector<float> times, std::vector<float> values,
                         int components) {
  AnimSampler s;
  s.interpolation = interp;
  s.times = std::move(times);
  s.values = std::move(values);
  s.components = components;
  return s;
}

TEST(Sampler, StepHoldsTheEarlierKey) {
  const AnimSampler s = make_sampler(Interpolation::kStep, {0, 1, 2}, {10, 20, 30}, 1);
  float v;
  sample(s, 0.99f, false, &v);
  EXPECT_EQ(v, 10.0f);
  sample(s, 1.0f, false, &v);
  EXPECT_EQ(v, 20.0f);
  sample(s, 5.0f, false, &v);
  EXPECT_EQ(v, 30.0f);
}

TEST(Sampler, CubicSplineIsHermiteWithScaledTangents) {
  // Keys at t = 0 and 2: values 0 and 1, out-tangent of key 0 = 1, in-tangent of key 1 = 0.
  // Hermite at u = 0.5 with dt = 2: h00 0.5, h10 0.125, h01 0.5, h11 -0.125:
  // 0.5*0 + 0.125*2*1 + 0.5*1 + (-0.125)*2*0 = 0.75.
  const AnimSampler s =
      make_sampler(Interpolation::kCubicSpline, {0, 2}, {0, 0, 1, /**/ 0, 1, 0}, 1);
  float v;
  sample(s, 1.0f, false, &v);
  EXPECT_NEAR(v, 0.75f, 1e-6f);
  sample(s, 2.0f, false, &v);
  EXPECT_NEAR(v, 1.0f, 1e-6f);
}

TEST(Sampler, LinearRotationIsSlerp) {
  // Identity to 90 deg about Y; a quarter of the way is 22.5 deg (nlerp would give ~20.7).
  const float h = std::sqrt(0.5f);
  const AnimSampler s = make_sampler(Interpolation::kLinear, {0, 1}, {0, 0, 0, 1, 0, h, 0, h}, 4);
  float q[4];
  sample(s, 0.25f, true, q);
  const float angle = 2.0f * std::acos(q[3]) * 180.0f / kPi;
  EXPECT_NEAR(angle, 22.5f, 1e-3f);
}

TEST(Morph, WeightsDisplaceVertices) {
  Scene s;
  Primitive p;
  p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  p.indices = {0, 1, 2};
  MorphTarget t;
  t.positions = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  p.targets.push_back(t);
  Mesh m;
  m.primitives.push_back(p);
  m.weights = {0.25f};
  s.meshes.push_back(m);
  Node n;
  n.mesh = 0;
  s.nodes.push_back(n);
  s.roots = {0};
  Animation a;
  a.samplers.push_back(make_sampler(Interpolation::kLinear, {0, 1}, {0, 1}, 1));
  a.channels.push_back({0, AnimPath::kWeights, 0});
  a.end = 1;
  s.animations.push_back(a);
  EXPECT_NEAR(pose_scene(s, -1, 0.0f).primitives[0].world_positions[1].z, 0.25f, 1e-6f);
  EXPECT_NEAR(pose_scene(s, 0, 0.5f).primitives[0].world_positions[1].z, 0.5f, 1e-6f);
}

TEST(Shot, AutoCameraFramesTheBounds) {
  Scene s;
  Bounds b{{-1, 0, -1}, {1, 2, 1}};
  ShotSpec shot;
  const ViewCamera cam = camera_at(shot, s, Pose{}, b, 0.0f, 16.0f / 9.0f);
  // The bounds' centre is on the optical axis and in front of the camera.
  const glm::vec3 c = glm::vec3(cam.view * glm::vec4(b.center(), 1.0f));
  EXPECT_NEAR(c.x, 0.0f, 1e-4f);
  EXPECT_NEAR(c.y, 0.0f, 1e-4f);
  EXPECT_LT(c.z, -1.0f);
}

TEST(Shot, GltfCameraFollowsItsAnimatedNode) {
  Scene s;
  CameraDef def;
  def.yfov = 0.5f;
  s.cameras.push_back(def);
  Node cam;
  cam.camera = 0;
  cam.translation = {0, 0, 5};
  s.nodes.push_back(cam);
  s.roots = {0};
  Animation a;
  a.samplers.push_back(make_sampler(Interpolation::kLinear, {0, 1}, {0, 0, 5, 2, 0, 5}, 3));
  a.channels.push_back({0, AnimPath::kTranslation, 0});
  a.end = 1;
  s.animations.push_back(a);
  ShotSpec shot;
  shot.camera.mode = CameraSpec::Mode::kGltf;
  shot.camera.gltf_node = 0;
  const ViewCamera cam0 = camera_at(shot, s, evaluate_pose(s, 0, 0.5f), Bounds{}, 0.0f, 1.0f);
  EXPECT_NEAR(cam0.tan_half_fov, std::tan(0.25f), 1e-6f);
  expect_near(cam0.position(), {1, 0, 5});
  // glTF cameras look down their local -Z: the world point (1, 0, 0) is straight ahead.
  const glm::vec3 ahead = glm::vec3(cam0.view * glm::vec4(1, 0, 0, 1));
  expect_near(ahead, {0, 0, -5});
}

}  // namespace
}  // namespace emaki::scene
