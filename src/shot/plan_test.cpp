// The farm plan: which tasks a shot becomes, what each waits for, and what resuming leaves out.
#include "shot/plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "shot/api.h"
#include "tests/small_painting.h"

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
  EXPECT_EQ(ids(p, TaskKind::kPrepare), std::vector<std::string>{"a.prepare"});
  EXPECT_EQ(ids(p, TaskKind::kPasses),
            (std::vector<std::string>{"a.passes.0-3", "a.passes.4-7", "a.passes.8-9"}));
  EXPECT_EQ(ids(p, TaskKind::kLayer),
            (std::vector<std::string>{"a.layer.base.0-9", "a.layer.ink.0-3", "a.layer.ink.4-7",
                                      "a.layer.ink.8-9"}));
  EXPECT_EQ(ids(p, TaskKind::kComposite).size(), 3u);
  EXPECT_EQ(ids(p, TaskKind::kPreviews), std::vector<std::string>{"a.previews"});
  // Each waits for the whole stage before it.
  EXPECT_EQ(task(p, "a.passes.4-7").after, std::vector<std::string>{"a.prepare"});
  EXPECT_EQ(task(p, "a.layer.ink.4-7").after, ids(p, TaskKind::kPasses));
  EXPECT_EQ(task(p, "a.composite.0-3").after, ids(p, TaskKind::kLayer));
  EXPECT_EQ(task(p, "a.previews").after, ids(p, TaskKind::kComposite));
  const Task& base = task(p, "a.layer.base.0-9");
  EXPECT_EQ(base.argv[1], "task");
  EXPECT_EQ(base.argv[2], "layer");
  EXPECT_NE(std::find(base.argv.begin(), base.argv.end(), "0-9"), base.argv.end());
  EXPECT_GT(base.memory_mb, 0);
  for (const Task& t : p.tasks) EXPECT_FALSE(t.done) << t.id;
}

TEST_F(PlanTest, ShotsGetUniqueNamesAndOwnTasks) {
  PlanOptions o;
  o.chunk = 100;
  std::vector<PlannedShot> shots = {shot("a", 3), shot("b", 5)};
  shots[1].name = "a";  // two shots with one name are told apart
  const Plan p = plan(std::move(shots), o);
  ASSERT_EQ(p.shots.size(), 2u);
  EXPECT_EQ(p.shots[1].name, "a-2");
  EXPECT_EQ(ids(p, TaskKind::kPrepare), (std::vector<std::string>{"a.prepare", "a-2.prepare"}));
  EXPECT_EQ(task(p, "a-2.layer.ink.0-5").after, std::vector<std::string>{"a-2.passes.0-5"});
  const std::string json = plan_json(p);
  EXPECT_NE(json.find("\"format\": \"emaki-plan-1\""), std::string::npos);
  EXPECT_NE(json.find("\"id\": \"a-2.previews\""), std::string::npos);
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
  EXPECT_TRUE(task(p, "a.prepare").done);
  EXPECT_TRUE(task(p, "a.passes.0-1").done);
  EXPECT_FALSE(task(p, "a.passes.2-3").done);
  EXPECT_TRUE(task(p, "a.layer.ink.0-1").done);
  EXPECT_FALSE(task(p, "a.layer.ink.2-3").done);
  EXPECT_FALSE(task(p, "a.layer.base.0-3").done);
  EXPECT_TRUE(task(p, "a.passes.2-3").after.empty());  // prepare is done
  EXPECT_EQ(task(p, "a.layer.ink.2-3").after, std::vector<std::string>{"a.passes.2-3"});

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

}  // namespace
}  // namespace emaki::shot
