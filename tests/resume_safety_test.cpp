// Work neither lost nor needlessly redone (issue 28): a full disk fails a run with one line naming
// the file and never commits a file cut short; a damaged output or pass-cache file is made again
// (by `run`, and by `run --force`) instead of stopping every later run; and the same shot reached
// through another spelling of its path (relative, absolute, through a linked folder) finds its
// finished frames current and redoes nothing.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>

#include "cli_run.h"
#include "core/image.h"
#include "io/image_io.h"
#include "tests/file_bytes.h"
#include "tests/small_disk.h"
#include "tests/small_painting.h"

namespace fs = std::filesystem;
using namespace emaki;

namespace {

const std::string kData = EMAKI_TEST_DATA;

// Fox walking (its file beside the shot), a small painting, a temporal base layer and an
// outline; every path relative to the shot file except the output folder's.
const char* kShot = R"(threads = 2
[source]
scene = "Fox.glb"
clip = "Walk"
frames = [0, 2]
size = [32, 24]
aa = 1

[exemplars.sphere]
painting = "painting.png"
sphere = [50.7, 41.2, 20.2]
elevation = 20
aa = 1

[layers.base]
kind = "base"
exemplar = "sphere"

[layers.outline]
kind = "outline"
exemplar = "sphere"

[outputs]
folder = "@FOLDER@"
mp4 = false
contact_sheet = false
)";

bool is_one_line(const std::string& s) {
  return test::count_lines(s) == 1 && s.back() == '\n';
}

// stderr without the progress lines (`emaki run: frame 3 layer base (...)`).
std::string without_progress(const std::string& err) {
  std::string out;
  std::size_t at = 0;
  while (at < err.size()) {
    std::size_t end = err.find('\n', at);
    end = end == std::string::npos ? err.size() : end + 1;
    const std::string line = err.substr(at, end - at);
    if (line.rfind("emaki run: frame ", 0) != 0) out += line;
    at = end;
  }
  return out;
}

class ResumeSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_resume_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "shot");
    test::write_small_painting(kData + "/stylit/source_style.png", p("shot/painting.png"));
    fs::copy_file(kData + "/scenes/Fox.glb", p("shot/Fox.glb"));
    write_shot("out");
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::string p(const std::string& name) const { return (dir_ / name).string(); }

  void write_shot(const std::string& folder) const {
    std::ofstream(p("shot/shot.toml")) << std::regex_replace(kShot, std::regex("@FOLDER@"), folder);
  }

  test::CliResult emaki(const std::string& args, const fs::path& cwd = {}) const {
    test::CliOptions o;
    o.cwd = cwd.empty() ? dir_ / "shot" : cwd;
    return test::run_cli(EMAKI_BINARY, test::split_args(args), o);
  }

  void expect_ok(const test::CliResult& r) const {
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.signal, 0) << r.err;
    EXPECT_FALSE(r.timed_out);
  }

  // Every image file emaki wrote under `folder` reads back (none is cut short).
  static int expect_all_readable(const fs::path& folder) {
    int n = 0;
    for (const auto& e : fs::recursive_directory_iterator(folder)) {
      const std::string ext = e.path().extension().string();
      if (!e.is_regular_file() || (ext != ".exr" && ext != ".png")) continue;
      EXPECT_NO_THROW(io::read_image_float(e.path().string())) << e.path();
      ++n;
    }
    return n;
  }

  fs::path dir_;
};

void cut_to_half(const std::string& path) {
  fs::resize_file(path, fs::file_size(path) / 2);
}

// ---- damaged files ----

// A pass-cache file and a layer file cut short (what a full disk left before) stop neither
// `run --force` nor `task passes`: the cached frame is rendered instead and made again.
TEST_F(ResumeSafety, TruncatedCacheAndLayerFilesAreReplacedByRunForce) {
  expect_ok(emaki("task prepare shot.toml"));
  expect_ok(emaki("task passes shot.toml --frames 0-2"));
  expect_ok(emaki("run shot.toml"));
  cut_to_half(p("shot/out/passes/frame_0001.passes"));
  cut_to_half(p("shot/out/layers/base/base_0001.exr"));
  cut_to_half(p("shot/out/composite/frame_0002.png"));
  const test::CliResult r = emaki("run --force shot.toml");
  expect_ok(r);
  EXPECT_NE(r.err.find("6 layer-frames synthesized"), std::string::npos) << r.err;
  expect_ok(emaki("task passes shot.toml --frames 0-2"));
  EXPECT_GT(expect_all_readable(dir_ / "shot/out"), 10);
}

// The advection fields the passes tasks keep (passes/advection_NNNN.field, one file per frame
// after the first) give the layer tasks a run's frames; a field file cut short or with a byte
// changed is not read (the layer task computes its fields) and gives the same frames.
TEST_F(ResumeSafety, LayerTasksMakeARunsFramesFromKeptOrDamagedFields) {
  expect_ok(emaki("run shot.toml"));
  write_shot("farm");
  expect_ok(emaki("task prepare shot.toml"));
  expect_ok(emaki("task passes shot.toml --frames 0-1"));
  expect_ok(emaki("task passes shot.toml --frames 2-2"));
  EXPECT_FALSE(fs::exists(p("shot/farm/passes/advection_0000.field")));
  EXPECT_TRUE(fs::exists(p("shot/farm/passes/advection_0001.field")));
  EXPECT_TRUE(fs::exists(p("shot/farm/passes/advection_0002.field")));
  const auto same_as_run = [&] {
    for (const char* layer : {"base", "outline"}) {
      std::string task = "task layer shot.toml --layer ";
      task += layer;
      expect_ok(emaki(task));
      for (int f = 0; f <= 2; ++f) {
        char name[64];
        std::snprintf(name, sizeof name, "/layers/%s/%s_%04d.exr", layer, layer, f);
        EXPECT_EQ(test::file_bytes(p(std::string("shot/out") + name)),
                  test::file_bytes(p(std::string("shot/farm") + name)))
            << name;
        fs::remove(p(std::string("shot/farm") + name));
      }
    }
  };
  same_as_run();
  cut_to_half(p("shot/farm/passes/advection_0001.field"));
  {
    std::fstream f(p("shot/farm/passes/advection_0002.field"),
                   std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(1000);
    f.put('\x7f');
  }
  same_as_run();
}

// Without --force, a damaged frame is not finished: `run` makes that one again.
TEST_F(ResumeSafety, ADamagedOutputIsMadeAgainByAPlainRun) {
  expect_ok(emaki("run shot.toml"));
  cut_to_half(p("shot/out/layers/outline/outline_0002.exr"));
  cut_to_half(p("shot/out/layered/frame_0001.exr"));
  const test::CliResult r = emaki("run shot.toml");
  expect_ok(r);
  EXPECT_NE(r.err.find("1 layer-frames synthesized, 5 already finished, 2 frames composited"),
            std::string::npos)
      << r.err;
  EXPECT_GT(expect_all_readable(dir_ / "shot/out"), 10);
}

// ---- a full disk ----

// The shot's outputs on a small tmpfs filled to many points: each run either finishes or fails
// with one line naming a file in the folder, and the run after it (with room) finishes with the
// same files as a run that never met a full disk.
TEST_F(ResumeSafety, AFullDiskNeverCommitsAFileCutShort) {
  test::SmallDisk disk("resume", 8 << 20);
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (needs root)";
  write_shot(disk / "out");
  const int64_t empty = disk.free_bytes();
  expect_ok(emaki("run shot.toml"));
  const int64_t used = empty - disk.free_bytes();
  std::map<std::string, std::string> want;
  for (const auto& e : fs::recursive_directory_iterator(disk / "out"))
    if (e.is_regular_file() && e.path().filename().string()[0] != '.')
      want[fs::relative(e.path(), disk.path()).string()] = test::slurp_file(e.path());
  ASSERT_GT(want.size(), 10u);
  int failed = 0;
  for (int k = 0; k < 10; ++k) {
    fs::remove_all(disk / "out");
    ASSERT_TRUE(disk.leave_free(used * k / 10 / 4096 * 4096));
    const test::CliResult full = emaki("run shot.toml");
    disk.release();
    if (full.exit_code != 0) {
      ++failed;
      const std::string error = without_progress(full.err);
      EXPECT_EQ(full.exit_code, 1) << error;
      EXPECT_TRUE(is_one_line(error)) << error;
      EXPECT_EQ(error.rfind("emaki run: error: " + disk.path().string(), 0), 0u) << error;
    }
    expect_ok(emaki("run shot.toml"));
    for (const auto& [name, bytes] : want)
      EXPECT_TRUE(test::slurp_file(disk / name) == bytes) << name << " after filling to " << k;
  }
  EXPECT_GT(failed, 5);
}

// ---- the same shot by another path ----

struct Stamp {
  ino_t inode = 0;
  int64_t mtime_ns = 0;
  bool operator==(const Stamp&) const = default;
};

std::map<std::string, Stamp> stamps(const fs::path& folder) {
  std::map<std::string, Stamp> out;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    struct stat st {};
    // The lock file names each run's holder: it is written by every run.
    if (!e.is_regular_file() || e.path().filename() == ".emaki.lock" ||
        ::stat(e.path().c_str(), &st) != 0)
      continue;
    out[fs::relative(e.path(), folder).string()] = {
        st.st_ino, int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
  }
  return out;
}

// Run by a relative path, then by the absolute one, through a linked folder and from another
// folder: every frame is already finished and no file is touched. Before, manifests held the
// paths as spelled and the second run deleted and redid every frame.
TEST_F(ResumeSafety, AnotherSpellingOfTheShotsPathRedoesNothing) {
  expect_ok(emaki("run shot.toml"));
  const auto before = stamps(dir_ / "shot/out");
  ASSERT_GT(before.size(), 10u);
  fs::create_directory_symlink(dir_ / "shot", dir_ / "linked");
  for (const auto& [args, cwd] : std::vector<std::pair<std::string, fs::path>>{
           {"run " + p("shot/shot.toml"), dir_},
           {"run " + p("linked/shot.toml"), "/"},
           {"run shot/shot.toml", dir_},
           {"run ../linked/./shot.toml", dir_ / "shot"}}) {
    const test::CliResult r = emaki(args, cwd);
    expect_ok(r);
    EXPECT_NE(r.err.find("0 layer-frames synthesized, 6 already finished, 0 frames composited"),
              std::string::npos)
        << args << ": " << r.err;
    const auto after = stamps(dir_ / "shot/out");
    for (const auto& [name, stamp] : before)
      EXPECT_TRUE(after.count(name) && after.at(name) == stamp) << args << ": " << name;
  }
  // The farm's plan, given absolute paths, finds the shot finished.
  const test::CliResult plan = emaki("plan --json " + p("linked/shot.toml"), "/");
  expect_ok(plan);
  EXPECT_EQ(plan.out.find("\"done\": false"), std::string::npos) << plan.out;
  EXPECT_NE(plan.out.find("\"done\": true"), std::string::npos) << plan.out;
}

}  // namespace
