#include "scene/assembly.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "io/gltf_loader.h"

namespace emaki::scene {
namespace {

const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";
constexpr float kFps = 24.0f;

// The primitives an assembled pose draws for one object id, in drawing order.
std::vector<const PosedPrimitive*> of_object(const PosedScene& posed, int id) {
  std::vector<const PosedPrimitive*> out;
  for (const PosedPrimitive& p : posed.primitives)
    if (p.object_id == id) out.push_back(&p);
  return out;
}

// The clip time a placement's clip is at, shot time t: its first key + start + t, wrapped when
// it loops.
float clip_time(const Placement& p, float t) {
  if (p.animation < 0) return 0.0f;
  const Animation& a = p.asset->animations[p.animation];
  double x = double(t) + p.start;
  const double length = double(a.end) - a.start;
  if (p.loop) x -= std::floor(x / length) * length;
  return float(a.start + x);
}

// Three assets, each with its own transform, clip, start and loop (the fox also walks): at every
// frame each object's vertices are where its own file, posed at its own clip time and placed,
// puts them.
TEST(Assembly, ObjectsPoseAsTheirClipsSay) {
  const Scene box = io::load_gltf(kScenes + "BoxAnimated.gltf");
  const Scene fox = io::load_gltf(kScenes + "Fox.glb");
  const Scene skin = io::load_gltf(kScenes + "SimpleSkin.gltf");
  std::vector<Placement> objects(3);
  objects[0] = {&box, {3, 0, -2}, {0, 90, 0}, glm::vec3(2.0f), {}, 0, 1.0, true, 5};
  objects[1] = {&fox,
                {-1, 0, 4},
                {0, -45, 0},
                glm::vec3(0.02f),
                {0, 0, 1.5f},
                fox.find_animation("Walk"),
                0.25,
                true,
                0};
  objects[2] = {&skin, {0, 0, 0}, {90, 0, 30}, {1, 2, 1}, {}, 0, 0.5, false, 3};
  const Scene s = assemble(objects);
  ASSERT_EQ(s.animations.size(), 1u);
  EXPECT_EQ(s.animations[0].name, kAssemblyClip);
  for (int f : {0, 7, 20, 47}) {
    const float t = float(f / double(kFps));
    const PosedScene posed = pose_scene(s, 0, t);
    for (const Placement& p : objects) {
      const PosedScene own = pose_scene(*p.asset, p.animation, clip_time(p, t));
      Placement at = p;
      at.translate += t * p.velocity;
      const glm::mat4 m = placement_matrix(at);
      const std::vector<const PosedPrimitive*> got = of_object(posed, p.object_id);
      ASSERT_EQ(got.size(), own.primitives.size()) << "frame " << f << " id " << p.object_id;
      float worst = 0.0f, size = glm::length(world_bounds(own).size()) * p.scale.y;
      for (std::size_t k = 0; k < got.size(); ++k) {
        const std::vector<glm::vec3>& want = own.primitives[k].world_positions;
        ASSERT_EQ(got[k]->world_positions.size(), want.size());
        for (std::size_t v = 0; v < want.size(); ++v) {
          const glm::vec3 w = glm::vec3(m * glm::vec4(want[v], 1.0f));
          worst = std::max(worst, glm::length(got[k]->world_positions[v] - w));
        }
      }
      EXPECT_LT(worst, 1e-4f * size + 1e-5f) << "frame " << f << " id " << p.object_id;
    }
  }
}

// Every mesh an object draws carries its id; no two objects share a material (an asset without
// materials gets a default of its own), the same asset placed twice included.
TEST(Assembly, IdsStayUniqueAcrossAssets) {
  const Scene alien = io::load_gltf(kScenes + "alien.glb");
  const Scene skin = io::load_gltf(kScenes + "SimpleSkin.gltf");
  std::vector<Placement> objects(4);
  objects[0] = {&alien, {}, {}, glm::vec3(1.0f), {}, -1, 0.0, false, 0};
  objects[1] = {&alien, {2, 0, 0}, {}, glm::vec3(1.0f), {}, -1, 0.0, false, 1};
  objects[2] = {&skin, {}, {}, glm::vec3(1.0f), {}, 0, 0.0, true, 7};
  objects[3] = {&skin, {4, 0, 0}, {}, glm::vec3(1.0f), {}, 0, 0.0, true, 3};
  const Scene s = assemble(objects);
  const PosedScene posed = pose_scene(s, 0, 0.5f);
  std::vector<std::set<int>> materials(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const std::vector<const PosedPrimitive*> prims = of_object(posed, objects[k].object_id);
    EXPECT_EQ(prims.size(), pose_scene(*objects[k].asset, -1, 0.0f).primitives.size());
    for (const PosedPrimitive* p : prims) {
      ASSERT_GE(p->material, 0);
      materials[k].insert(p->material);
    }
  }
  std::set<int> all;
  std::size_t total = 0;
  for (const auto& m : materials) all.insert(m.begin(), m.end()), total += m.size();
  EXPECT_EQ(all.size(), total);
  EXPECT_EQ(materials[0].size(), 5u);  // alien.glb's five materials, twice
  EXPECT_EQ(posed.primitives.size(), 2 * 18u + 2);
}

// Rest positions: each asset's rest pose fills the unit cube, whatever its size (the Cornell box
// is 550 units wide, the cake 0.3), stays put while the object moves, and a mesh drawn by
// several nodes (the cake's slices) gets its own rest positions per node.
TEST(Assembly, RestPositionsAreEachAssetsRestPoseInTheUnitCube) {
  const Scene cake = io::load_gltf(kScenes + "cakeBirthday.glb");
  const Scene box = io::load_gltf(kScenes + "CornellBox.glb");
  std::vector<Placement> objects(2);
  objects[0] = {&cake, {}, {}, glm::vec3(100.0f), {1, 0, 0}, -1, 0.0, false, 0};
  objects[1] = {&box, {}, {}, glm::vec3(0.5f), {}, -1, 0.0, false, 1};
  const Scene s = assemble(objects);
  const PosedScene a = pose_scene(s, 0, 0.0f), b = pose_scene(s, 0, 2.0f);
  ASSERT_EQ(a.primitives.size(), b.primitives.size());
  for (int id : {0, 1}) {
    Bounds rest;
    for (const PosedPrimitive* p : of_object(a, id))
      for (const glm::vec3& r : *p->rest_positions) rest.add(r);
    const float side = std::max({rest.size().x, rest.size().y, rest.size().z});
    EXPECT_NEAR(side, 1.0f, 1e-5f) << id;
    EXPECT_GE(std::min({rest.lo.x, rest.lo.y, rest.lo.z}), -1e-6f) << id;
    EXPECT_LE(std::max({rest.hi.x, rest.hi.y, rest.hi.z}), 1.0f + 1e-6f) << id;
  }
  for (std::size_t k = 0; k < a.primitives.size(); ++k)
    EXPECT_EQ(a.primitives[k].rest_positions, b.primitives[k].rest_positions);
  // Five slices draw one mesh of the file, a sixth another: six meshes here, and the copies'
  // rest positions are where each slice stands.
  const std::vector<const PosedPrimitive*> cake_prims = of_object(a, 0);
  std::set<int> meshes;
  for (const PosedPrimitive* p : cake_prims) meshes.insert(p->mesh);
  EXPECT_EQ(meshes.size(), 6u);
  int copies = 0, apart = 0;
  for (const PosedPrimitive* p : cake_prims)
    if (p->mesh != cake_prims[0]->mesh && p->primitive == 0 &&
        p->rest_positions->size() == cake_prims[0]->rest_positions->size()) {
      ++copies;
      apart += glm::length((*p->rest_positions)[0] - (*cake_prims[0]->rest_positions)[0]) > 1e-3f;
    }
  EXPECT_GE(copies, 4);
  EXPECT_EQ(apart, copies);
}

}  // namespace
}  // namespace emaki::scene
