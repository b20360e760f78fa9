// source.objects: parsed with their defaults and key-path errors, opened into one scene whose
// passes carry each object's id, and written into the manifests that resuming trusts.
#include "shot/objects.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "core/error.h"
#include "io/gltf_loader.h"
#include "render/passes.h"
#include "scene/assembly.h"
#include "shot/api.h"
#include "shot/inputs.h"
#include "store/settings_manifests.h"

namespace emaki::shot {
namespace {

const std::string kData = EMAKI_TEST_DATA;

std::string object(const std::string& file, const std::string& keys = "") {
  return "[[source.objects]]\nscene = \"" + kData + "/scenes/" + file + "\"\n" + keys;
}

std::string shot_text(const std::string& objects, const std::string& source_keys = "") {
  return "[source]\nframes = [0, 3]\nsize = [96, 64]\naa = 1\n" + source_keys + objects +
         "[source.camera]\nazimuth = 20\n[exemplars.sphere]\npainting = \"" + kData +
         "/stylit/source_style.png\"\n[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n" +
         "[outputs]\nfolder = \"/tmp/emaki_objects_test_out\"\n";
}

std::string error_of(const std::string& text) {
  try {
    open_frames(open_text(text, "/tmp/shot.toml"));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const std::string kThree =
    object("Fox.glb", "clip = \"Walk\"\nloop = true\nscale = 0.01\nvelocity = [0, 0, 1]\n") +
    object("cakeBirthday.glb", "translate = [1.2, 0, 0]\nscale = [2, 3, 2]\nid = 9\n") +
    object("BoxAnimated.gltf", "translate = [-1.2, 0.25, 0]\nrotate = [0, 30, 0]\nscale = 0.5\n");

TEST(Objects, ParseWithTheirDefaults) {
  const pipeline::Shot s = open_text(shot_text(kThree), "/tmp/shot.toml");
  const std::vector<pipeline::SceneObject>& o = s.source.objects;
  ASSERT_EQ(o.size(), 3u);
  EXPECT_TRUE(s.source.scene_path.empty());
  EXPECT_EQ(s.source.shot.clip, scene::kAssemblyClip);
  EXPECT_EQ(o[0].id, 2);
  EXPECT_EQ(o[1].id, 9);
  EXPECT_EQ(o[2].id, 10);  // one past the largest so far
  EXPECT_EQ(o[0].scale, glm::vec3(0.01f));
  EXPECT_EQ(o[1].scale, glm::vec3(2, 3, 2));
  EXPECT_EQ(o[0].clip, "Walk");
  EXPECT_TRUE(o[0].loop);
  EXPECT_EQ(o[2].rotate_deg, glm::vec3(0, 30, 0));
  EXPECT_EQ(o[0].velocity, glm::vec3(0, 0, 1));
}

TEST(Objects, BadEntriesNameTheirKeyPath) {
  const std::string fox = object("Fox.glb");
  auto starts = [](const std::string& err, const std::string& with) {
    return err.rfind(with, 0) == 0 ? ::testing::AssertionSuccess()
                                   : ::testing::AssertionFailure() << err;
  };
  EXPECT_TRUE(starts(error_of(shot_text(fox + object("cakeBirthday.glb", "scale = [1, 0, 1]\n"))),
                     "source.objects[1].scale: each factor must be in ["));
  EXPECT_TRUE(starts(error_of(shot_text(fox + object("cakeBirthday.glb", "scale = -2\n"))),
                     "source.objects[1].scale: must be in ["));
  EXPECT_TRUE(starts(error_of(shot_text(object("Fox.glb", "tranlsate = [0, 0, 1]\n"))),
                     "source.objects[0].tranlsate: unknown key — did you mean 'translate'?"));
  EXPECT_TRUE(starts(error_of(shot_text(fox + object("cakeBirthday.glb", "id = 2\n"))),
                     "source.objects[1].id: id 2 is taken by source.objects[0]"));
  EXPECT_TRUE(starts(error_of(shot_text(fox + object("cakeBirthday.glb", "id = 1\n"))),
                     "source.objects[1].id: must be in [2, 65535]"));
  EXPECT_TRUE(starts(error_of(shot_text("[[source.objects]]\ntranslate = [0, 0, 0]\n")),
                     "source.objects[0].scene: is required"));
  EXPECT_TRUE(starts(error_of(shot_text(object("nope.glb"))), "source.objects[0].scene: no such"));
  EXPECT_TRUE(starts(error_of(shot_text(fox, "clip = \"Walk\"\n")),
                     "source.clip: applies to 'scene'; each of 'objects' has its own"));
  EXPECT_TRUE(starts(error_of(shot_text("", "objects = 3\n")), "source.objects: expected"));
  EXPECT_TRUE(starts(error_of(shot_text(fox, "scene = \"x.glb\"\n")),
                     "source: give one of 'scene', 'objects' or 'sequence'"));
  // Found when the assets are opened: the clip, and a frame past its end without a loop.
  EXPECT_TRUE(starts(error_of(shot_text(object("Fox.glb", "clip = \"Wlak\"\n"))),
                     "source.objects[0].clip: no clip 'Wlak' in"));
  EXPECT_TRUE(starts(error_of(shot_text(object("Fox.glb", "clip = \"Walk\"\nstart = 0.6\n"))),
                     "source.objects[0].loop: frame 3 is at 0.725 s of clip 'Walk'"));
  EXPECT_TRUE(starts(error_of(shot_text(object("Fox.glb", "clip = \"Walk\"\nstart = 2\n"))),
                     "source.objects[0].start: 2 s is outside clip 'Walk'"));
}

// Through the renderer: every covered pixel carries the ground's id or one of the objects', each
// object is seen, and no material id is shared by two objects.
TEST(Objects, PassesCarryEachObjectsIds) {
  const pipeline::Shot s = open_text(shot_text(kThree), "/tmp/shot.toml");
  const auto frames = open_frames(s);
  for (int f : {0, 3}) {
    const Image<float> p = frames->passes(f);
    std::map<int, std::set<int>> materials;
    for (int y = 0; y < p.height(); ++y)
      for (int x = 0; x < p.width(); ++x)
        if (p(x, y, render::kAlpha) > 0.0f)
          materials[int(p(x, y, render::kObjectId))].insert(int(p(x, y, render::kMaterialId)));
    std::set<int> ids;
    for (const auto& [id, m] : materials) ids.insert(id);
    EXPECT_EQ(ids, (std::set<int>{1, 2, 9, 10})) << "frame " << f;
    std::set<int> all;
    std::size_t total = 0;
    for (const auto& [id, m] : materials) all.insert(m.begin(), m.end()), total += m.size();
    EXPECT_EQ(all.size(), total) << "frame " << f;
  }
}

// Resuming redoes what a changed object made: its placement, clip and file are in the manifest.
TEST(Objects, ManifestsHoldTheObjects) {
  const pipeline::Shot a = open_text(shot_text(kThree), "/tmp/shot.toml");
  pipeline::Shot b = a;
  b.source.objects[1].translate.x += 0.5f;
  pipeline::Shot c = a;
  c.source.objects[0].clip = "Run";
  const io::Manifest ma = io::layer_manifest(a, a.layers[0]);
  EXPECT_NE(ma, io::layer_manifest(b, b.layers[0]));
  EXPECT_NE(ma, io::layer_manifest(c, c.layers[0]));
  EXPECT_EQ(ma, io::layer_manifest(a, a.layers[0]));
}

// ---- one file, one load; one budget over the scene ----

// A folder with a link to Fox.glb and a link to the folder holding it: four spellings of one file.
class SharedAssets : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("emaki_objects_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    std::filesystem::create_symlink(kData + "/scenes/Fox.glb", dir_ / "fox_link.glb");
    std::filesystem::create_directory_symlink(kData + "/scenes", dir_ / "scenes_link");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // `n` Fox objects, their paths cycling through the four spellings.
  pipeline::Shot foxes(int n) const {
    const std::string spellings[4] = {kData + "/scenes/Fox.glb", (dir_ / "fox_link.glb").string(),
                                      (dir_ / "scenes_link/Fox.glb").string(),
                                      kData + "/scenes/../scenes/Fox.glb"};
    std::string objects;
    for (int i = 0; i < n; ++i)
      objects += "[[source.objects]]\nscene = \"" + spellings[i % 4] +
                 "\"\nclip = \"Walk\"\nloop = true\nscale = 0.01\n";
    return open_text(shot_text(objects), (dir_ / "shot.toml").string());
  }

  std::filesystem::path dir_;
};

// 256 objects of one file through four spellings of its path: one load, one texture, each
// placement's geometry copied. Before, each spelling was loaded and every placement cloned the
// texture (256 of them).
TEST_F(SharedAssets, OneFileIsLoadedOnceAndItsTexturesAreShared) {
  const scene::Scene fox = io::load_gltf(kData + "/scenes/Fox.glb");
  const scene::SceneBytes one = scene::scene_bytes(fox);
  ASSERT_EQ(fox.textures.size(), 1u);
  SceneCost cost;
  const scene::Scene s = load_objects(foxes(256).source, &cost);
  EXPECT_EQ(s.textures.size(), 1u);
  const scene::SceneBytes all = scene::scene_bytes(s);
  EXPECT_EQ(all.textures, one.textures);
  EXPECT_GT(all.geometry, 256 * one.geometry);
  // What was charged: the file once (textures and geometry) and every placement's copy.
  EXPECT_EQ(cost.bytes, all.total() + one.geometry);
  EXPECT_EQ(cost.drawn_vertices, 256 * int64_t(fox.meshes[0].primitives[0].positions.size()));
}

// Over the budget, the object that takes the scene over it is named, before its copy is made.
TEST_F(SharedAssets, ASceneOverItsBudgetNamesTheObjectThatTakesItOver) {
  SceneCost two;
  load_objects(foxes(2).source, &two);
  SceneCost three;
  load_objects(foxes(3).source, &three);
  try {
    load_objects(foxes(8).source, nullptr, (two.bytes + three.bytes) / 2);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "source.objects[2].scene") << e.what();
    EXPECT_NE(std::string(e.what()).find("at most"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace emaki::shot
