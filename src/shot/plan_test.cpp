// The farm plan: which tasks a shot becomes, what each waits for, and what resuming leaves out.
#include "shot/plan.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>

#include "core/error.h"
#include "core/utf8.h"
#include "shot/api.h"
#include "shot/objects.h"
#include "tests/small_painting.h"
#include "tests/textured_triangle.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

class PlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_plan_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (const char* sub : {"d1", "d2"}) fs::create_directories(dir_ / sub);
    test::write_small_painting(kData + "/stylit/source_style.png", painting());
  }
  std::string painting() const { return (dir_ / "painting.png").string(); }
  void TearDown() override { fs::remove_all(dir_); }

  // Frames [0, last]; `base` temporal, `ink` not.
  PlannedShot shot(const std::string& name, int last) const {
    const std::string text =
        "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\nframes = [0, " +
        std::to_string(last) + "]\nsize = [32, 20]\naa = 1\n[exemplars.sphere]\npainting = \"" +
        painting() + "\"\n[layers.base]\nkind = \"base\"\n" +
        "exemplar = \"sphere\"\n[layers.ink]\nkind = \"outline\"\nexemplar = \"sphere\"\n" +
        "temporal = false\n[outputs]\nfolder = \"" + (dir_ / name).string() + "\"\nmp4 = false\n";
    const std::string path = (dir_ / (name + ".toml")).string();
    return {"", path, open_text(text, path)};
  }

  static std::vector<std::string> ids(const Plan& p, TaskKind kind) {
    std::vector<std::string> out;
    for (const Task& t : p.tasks)
      if (t.kind == kind) out.push_back(t.id);
    return out;
  }
  static const Task& task(const Plan& p, const std::string& id) {
    const auto it =
        std::find_if(p.tasks.begin(), p.tasks.end(), [&](const Task& t) { return t.id == id; });
    EXPECT_NE(it, p.tasks.end()) << id;
    return *it;
  }

  fs::path dir_;
};

TEST_F(PlanTest, TemporalLayersAreOneTaskOthersAreChunked) {
  PlanOptions o;
  o.chunk = 4;
  const Plan p = plan(std::vector<PlannedShot>{shot("a", 9)}, o);
  const std::string a = p.shots[0].name;
  EXPECT_EQ(ids(p, TaskKind::kPrepare), std::vector<std::string>{a + ".prepare"});
  EXPECT_EQ(ids(p, TaskKind::kPasses),
            (std::vector<std::string>{a + ".passes.0-3", a + ".passes.4-7", a + ".passes.8-9"}));
  EXPECT_EQ(ids(p, TaskKind::kLayer),
            (std::vector<std::string>{a + ".layer.base.0-9", a + ".layer.ink.0-3",
                                      a + ".layer.ink.4-7", a + ".layer.ink.8-9"}));
  EXPECT_EQ(ids(p, TaskKind::kComposite).size(), 3u);
  EXPECT_EQ(ids(p, TaskKind::kPreviews), std::vector<std::string>{a + ".previews"});
  // A chunk waits for the tasks that make its frames; a temporal layer for every chunk.
  EXPECT_EQ(task(p, a + ".passes.4-7").after, std::vector<std::string>{a + ".prepare"});
  EXPECT_EQ(task(p, a + ".layer.ink.4-7").after, std::vector<std::string>{a + ".passes.4-7"});
  EXPECT_EQ(task(p, a + ".layer.base.0-9").after, ids(p, TaskKind::kPasses));
  EXPECT_EQ(
      task(p, a + ".composite.4-7").after,
      (std::vector<std::string>{a + ".passes.4-7", a + ".layer.base.0-9", a + ".layer.ink.4-7"}));
  EXPECT_EQ(task(p, a + ".previews").after, ids(p, TaskKind::kComposite));
  const Task& base = task(p, a + ".layer.base.0-9");
  EXPECT_EQ(base.argv[1], "task");
  EXPECT_EQ(base.argv[2], "layer");
  EXPECT_NE(std::find(base.argv.begin(), base.argv.end(), "0-9"), base.argv.end());
  EXPECT_GT(base.memory_mb, 0);
  for (const Task& t : p.tasks) EXPECT_FALSE(t.done) << t.id;
}

// d1/a.toml, d2/a.toml and a-2.toml: one stem, and a name the old "-2" suffix would have made.
// Each gets its own task ids (stem plus a digest of its canonical path, the same in any plan)
// and its own dependencies.
TEST_F(PlanTest, ShotsWithOneStemGetDistinctStableNames) {
  PlanOptions o;
  o.chunk = 100;
  const Plan p =
      plan(std::vector<PlannedShot>{shot("d1/a", 3), shot("d2/a", 5), shot("a-2", 4)}, o);
  ASSERT_EQ(p.shots.size(), 3u);
  std::set<std::string> names;
  for (const PlannedShot& s : p.shots) {
    names.insert(s.name);
    EXPECT_EQ(s.name.size(), fs::path(s.path).stem().string().size() + 9) << s.name;
    EXPECT_EQ(s.name.rfind(fs::path(s.path).stem().string() + "-", 0), 0u) << s.name;
  }
  EXPECT_EQ(names.size(), 3u);
  std::set<std::string> all;
  for (const Task& t : p.tasks) EXPECT_TRUE(all.insert(t.id).second) << t.id;
  for (const PlannedShot& s : p.shots) {
    const int last = s.shot.source.last_frame;
    EXPECT_EQ(task(p, fmt::format("{}.layer.ink.0-{}", s.name, last)).after,
              std::vector<std::string>{fmt::format("{}.passes.0-{}", s.name, last)});
    EXPECT_EQ(task(p, s.name + ".previews").after,
              std::vector<std::string>{fmt::format("{}.composite.0-{}", s.name, last)});
  }
  // Planned alone, a shot keeps its name: status and cancel find what submit recorded.
  EXPECT_EQ(plan(std::vector<PlannedShot>{shot("d2/a", 5)}, o).shots[0].name, p.shots[1].name);
  std::vector<PlannedShot> twins = {shot("b", 3), shot("c", 3)};
  twins[0].name = twins[1].name = "same";
  EXPECT_THROW(plan(std::move(twins), o), Error);
  const std::string json = plan_json(p);
  EXPECT_NE(json.find("\"format\": \"emaki-plan-1\""), std::string::npos);
  EXPECT_NE(json.find("\"id\": \"" + p.shots[2].name + ".previews\""), std::string::npos);
}

// JSON is Unicode: a path that is not UTF-8 is an error naming the shot, never invalid JSON.
TEST_F(PlanTest, JsonRefusesPathsThatAreNotUtf8) {
  PlannedShot latin1 = shot("a", 1);  // TOML text is UTF-8; a file name need not be
  latin1.path = (dir_ / "caf\xe9.toml").string();
  const Plan p = plan(std::vector<PlannedShot>{latin1}, PlanOptions{});
  try {
    plan_json(p);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("is not UTF-8"), std::string::npos) << e.what();
    EXPECT_EQ(first_invalid_utf8(e.what()), std::string::npos) << e.what();
  }
  const Plan ok = plan(std::vector<PlannedShot>{shot("caf\xc3\xa9 q", 1)}, PlanOptions{});
  EXPECT_NE(plan_json(ok).find("caf\xc3\xa9 q"), std::string::npos);
}

TEST_F(PlanTest, BadOptionsAndSharedFoldersAreErrors) {
  PlanOptions o;
  o.chunk = 0;
  try {
    plan(std::vector<PlannedShot>{shot("a", 3)}, o);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "chunk");
  }
  PlanOptions ok;
  PlannedShot twin = shot("a", 3);
  twin.path += ".copy";
  try {
    plan(std::vector<PlannedShot>{shot("a", 3), twin}, ok);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "shots");
  }
}

// A shot partly run: what is finished under current settings is done, the rest is left to do,
// and nothing waits on a done task.
TEST_F(PlanTest, ResumeLeavesOutFinishedWork) {
  PlanOptions o;
  o.chunk = 2;
  const PlannedShot s = shot("a", 3);
  Request r;
  r.farm_task = true;
  prepare(s.shot);
  r.first_frame = 0, r.last_frame = 1;
  render_passes(s.shot, r);
  r.layers = {"ink"};
  r.composite = false;
  run(s.shot, r);
  const Plan p = plan(std::vector<PlannedShot>{s}, o);
  const std::string a = p.shots[0].name;
  EXPECT_TRUE(task(p, a + ".prepare").done);
  EXPECT_TRUE(task(p, a + ".passes.0-1").done);
  EXPECT_FALSE(task(p, a + ".passes.2-3").done);
  EXPECT_TRUE(task(p, a + ".layer.ink.0-1").done);
  EXPECT_FALSE(task(p, a + ".layer.ink.2-3").done);
  EXPECT_FALSE(task(p, a + ".layer.base.0-3").done);
  EXPECT_TRUE(task(p, a + ".passes.2-3").after.empty());  // prepare is done
  EXPECT_EQ(task(p, a + ".layer.ink.2-3").after, std::vector<std::string>{a + ".passes.2-3"});

  // All of it run: every task is done, previews included.
  Request all;
  run(s.shot, all);
  const Plan finished = plan(std::vector<PlannedShot>{s}, o);
  for (const Task& t : finished.tasks) EXPECT_TRUE(t.done) << t.id;
}

// Farm tasks need the folder prepared: a layer task on a folder made under other settings
// refuses instead of deleting what other tasks are writing.
TEST_F(PlanTest, FarmTasksNeedAPreparedFolder) {
  const PlannedShot s = shot("a", 1);
  Request r;
  r.farm_task = true;
  r.layers = {"ink"};
  r.composite = false;
  EXPECT_THROW(run(s.shot, r), Error);
  prepare(s.shot);
  EXPECT_EQ(run(s.shot, r).report.synthesized, 2);
}

// A crowd of objects costs what its scene holds: the tasks that open it are estimated with it,
// the passes task also with the geometry it poses per frame. Here 256 objects of one triangle
// with a 2048 x 2048 texture (64 MiB as float RGBA), half of them through a link to the file;
// before, the estimate left the scene out (256 Fox objects peaked at 4.5 GB under 256 MB).
TEST_F(PlanTest, MemoryEstimatesCountTheScene) {
  const std::string tri = test::write_textured_triangle(dir_, 2048);
  fs::create_symlink(tri, dir_ / "link.gltf");
  std::string objects;
  for (int i = 0; i < 256; ++i)
    objects +=
        "[[source.objects]]\nscene = \"" + (i % 2 ? tri : (dir_ / "link.gltf").string()) + "\"\n";
  const std::string text = "[source]\nframes = [0, 1]\nsize = [32, 20]\naa = 1\n" + objects +
                           "[exemplars.sphere]\npainting = \"" + painting() +
                           "\"\n[layers.ink]\nkind = \"outline\"\nexemplar = \"sphere\"\n" +
                           "[outputs]\nfolder = \"" + (dir_ / "crowd").string() +
                           "\"\nmp4 = false\n";
  const std::string path = (dir_ / "crowd.toml").string();
  const PlannedShot crowd{"", path, open_text(text, path)};
  // The same shot with one Fox (its scene under a megabyte) as the measure of the rest.
  PlannedShot fox = shot("fox", 1);
  const Plan p = plan(std::vector<PlannedShot>{crowd, fox}, PlanOptions{});
  SceneCost cost;
  load_scene(crowd.shot.source, &cost);
  const double opened_mb = double(cost.bytes) / 1e6;
  ASSERT_GT(opened_mb, 64.0);
  ASSERT_LT(opened_mb, 80.0);  // the texture once
  // Estimates are rounded up to 64 MB and carry a quarter of margin.
  const std::string c = p.shots[0].name + ".", f = p.shots[1].name + ".";
  for (const char* kind : {"prepare", "composite.0-1", "passes.0-1"}) {
    const double more = double(task(p, c + kind).memory_mb - task(p, f + kind).memory_mb);
    EXPECT_GE(more, 1.25 * opened_mb - 64 - 2) << kind;
  }
  EXPECT_EQ(task(p, c + "previews").memory_mb, task(p, f + "previews").memory_mb);
}
}  // namespace
}  // namespace emaki::shot
