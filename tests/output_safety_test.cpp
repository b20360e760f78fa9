// Output safety (issue 9): emaki writes into folders users share with their own files, so it
// must never delete or overwrite what it did not make (hidden *.tmp* files, planted symlinks),
// never let two processes write one output folder at once, and never trust outputs made with
// other settings (a resize, a single_colour toggle) when resuming.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <thread>

#include "cli_run.h"
#include "core/image.h"
#include "io/image_io.h"
#include "tests/small_painting.h"
#include "tests/test_dir.h"

namespace fs = std::filesystem;
using namespace emaki;

namespace {

const std::string kData = EMAKI_TEST_DATA;

// Fox walking, a tiny copy of the StyLit painting as exemplar, base + outline layers.
const char* kShot = R"(threads = 2
[source]
scene = "@DATA@/scenes/Fox.glb"
clip = "Walk"
frames = [0, @LAST@]
size = [@W@, @H@]
aa = 1

[exemplars.sphere]
painting = "painting.png"
sphere = [50.7, 41.2, 20.2]
elevation = 20
aa = 1

[layers.base]
kind = "base"
exemplar = "sphere"
@BASE_EXTRA@

[layers.outline]
kind = "outline"
exemplar = "sphere"

[outputs]
folder = "@FOLDER@"
mp4 = @MP4@
contact_sheet = @SHEET@
)";

struct ShotText {
  int last = 1, w = 32, h = 24;
  std::string base_extra, folder = "out";
  bool sheet = false;
  bool mp4 = false;
};

std::string slurp(const fs::path& p) {
  return test::slurp_file(p);
}

bool is_one_line(const std::string& s) {
  return test::count_lines(s) == 1 && s.back() == '\n';
}

class OutputSafety : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_test_dir("emaki_outsafe");
    test::write_small_painting(kData + "/stylit/source_style.png", p("painting.png"));
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::string p(const std::string& name) const { return (dir_ / name).string(); }

  void write_shot(const ShotText& t, const std::string& name = "shot.toml") const {
    std::string s = kShot;
    auto put = [&](const char* key, const std::string& v) {
      s = std::regex_replace(s, std::regex(key), v);
    };
    put("@DATA@", kData);
    put("@LAST@", std::to_string(t.last));
    put("@W@", std::to_string(t.w));
    put("@H@", std::to_string(t.h));
    put("@BASE_EXTRA@", t.base_extra);
    put("@FOLDER@", t.folder);
    put("@SHEET@", t.sheet ? "true" : "false");
    put("@MP4@", t.mp4 ? "true" : "false");
    std::ofstream(p(name)) << s;
  }

  test::CliResult emaki(const std::string& args) const {
    test::CliOptions o;
    o.cwd = dir_;
    return test::run_cli(EMAKI_BINARY, test::split_args(args), o);
  }

  // Exit 0, no signal, no time-out.
  void expect_ok(const test::CliResult& r) const {
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.signal, 0) << r.err;
    EXPECT_FALSE(r.timed_out);
  }
  // Exit 1 with one line naming `subject`.
  void expect_error(const test::CliResult& r, const std::string& subject) const {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(r.signal, 0) << r.err;
    EXPECT_FALSE(r.timed_out);
    EXPECT_TRUE(is_one_line(r.err)) << r.err;
    EXPECT_NE(r.err.find(subject), std::string::npos) << "expected " << subject << " in: " << r.err;
  }

  // Every image file of kind `ext` under `folder`, with its size.
  void expect_all_sized(const fs::path& folder, const std::string& ext, int w, int h) const {
    int seen = 0;
    for (const auto& e : fs::recursive_directory_iterator(folder)) {
      if (!e.is_regular_file() || e.path().extension() != ext) continue;
      if (e.path().filename().string()[0] == '.') continue;
      if (e.path().filename() == "contact_sheet.png") continue;
      // The exemplars' reference passes are at their painting's size (store/reference_cache.h).
      if (e.path().parent_path().filename() == "references") continue;
      const Image<float> img = io::read_image_float(e.path().string());
      EXPECT_EQ(img.width(), w) << e.path();
      EXPECT_EQ(img.height(), h) << e.path();
      ++seen;
    }
    EXPECT_GT(seen, 0) << folder << " " << ext;
  }

  fs::path dir_;
};

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

// ---- temporaries and clean-up ----

TEST_F(OutputSafety, HiddenUserFilesInTheOutputFolderSurvive) {
  ShotText t;
  t.folder = ".";  // the shot's own folder, where the user keeps other files
  write_shot(t);
  write_text(dir_ / ".vimrc.tmp", "set nocompatible\n");
  write_text(dir_ / ".x.tmp123.png", "not an image\n");
  // emaki's own temporary pattern but for a file emaki never writes: still the user's.
  write_text(dir_ / ".notes.emaki-tmp-0123456789abcdef.txt", "mine\n");
  fs::create_directories(dir_ / "composite");
  write_text(dir_ / "composite/.frame_0000.tmp42.png", "old-style name, not ours to judge\n");
  // A temporary a killed emaki left behind: removed.
  write_text(dir_ / "composite/.frame_0000.emaki-tmp-0123456789abcdef.png", "left over\n");
  // ... also beside the QA maps (qa/KIND/LAYER/), but not in a linked folder there.
  fs::create_directories(dir_ / "qa/error/base");
  write_text(dir_ / "qa/error/base/.frame_0000.emaki-tmp-0123456789abcdef.png", "left over\n");
  // ... and beside the farm's pass cache and the exemplars' reference passes.
  for (const char* left : {"passes/.frame_0000.emaki-tmp-0123456789abcdef.passes",
                           "passes/.advection_0001.emaki-tmp-0123456789abcdef.field",
                           "references/.0123456789abcdef.emaki-tmp-0123456789abcdef.passes"}) {
    fs::create_directories((dir_ / left).parent_path());
    write_text(dir_ / left, "left over\n");
  }
  fs::create_directories(dir_ / "elsewhere");
  write_text(dir_ / "elsewhere/.frame_0000.emaki-tmp-0123456789abcdef.png", "not here\n");
  fs::create_directory_symlink(dir_ / "elsewhere", dir_ / "qa/error/linked");
  // A symlink with emaki's pattern is never removed (nor its target touched).
  write_text(dir_ / "victim.txt", "precious\n");
  fs::create_symlink(dir_ / "victim.txt",
                     dir_ / "composite/.frame_0001.emaki-tmp-fedcba9876543210.png");

  expect_ok(emaki("run " + p("shot.toml")));
  EXPECT_EQ(slurp(dir_ / ".vimrc.tmp"), "set nocompatible\n");
  EXPECT_EQ(slurp(dir_ / ".x.tmp123.png"), "not an image\n");
  EXPECT_EQ(slurp(dir_ / ".notes.emaki-tmp-0123456789abcdef.txt"), "mine\n");
  EXPECT_TRUE(fs::exists(dir_ / "composite/.frame_0000.tmp42.png"));
  EXPECT_FALSE(fs::exists(dir_ / "composite/.frame_0000.emaki-tmp-0123456789abcdef.png"));
  EXPECT_FALSE(fs::exists(dir_ / "qa/error/base/.frame_0000.emaki-tmp-0123456789abcdef.png"));
  EXPECT_TRUE(fs::exists(dir_ / "elsewhere/.frame_0000.emaki-tmp-0123456789abcdef.png"));
  EXPECT_TRUE(fs::is_empty(dir_ / "passes"));
  EXPECT_FALSE(fs::exists(dir_ / "references/.0123456789abcdef.emaki-tmp-0123456789abcdef.passes"));
  EXPECT_TRUE(fs::is_symlink(dir_ / "composite/.frame_0001.emaki-tmp-fedcba9876543210.png"));
  EXPECT_EQ(slurp(dir_ / "victim.txt"), "precious\n");
  EXPECT_TRUE(fs::is_regular_file(dir_ / "composite/frame_0001.png"));
}

TEST_F(OutputSafety, PlantedSymlinksAreNeverWrittenThrough) {
  ShotText t;
  t.last = 5;
  t.w = 64;
  t.h = 48;
  write_shot(t);
  fs::create_directories(dir_ / "out/composite");
  write_text(dir_ / "victim.txt", "precious\n");
  write_text(dir_ / "victim2.txt", "also precious\n");
  // At the final name: the finished file replaces the link, the link's target is untouched.
  fs::create_symlink(dir_ / "victim2.txt", dir_ / "out/composite/frame_0005.png");

  const std::string err_path = p("stderr.txt");
  const pid_t pid = test::spawn_cli(EMAKI_BINARY, {"run", p("shot.toml")}, err_path);
  ASSERT_GE(pid, 0);
  // Temporaries used to be ".<stem>.tmp<pid><ext>": once the run is under way (past its
  // start-up clean-up), plant links at the names its later frames would have used.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!fs::exists(dir_ / "out/layers/base/base_0000.exr") &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const std::string tag = ".tmp" + std::to_string(pid);
  int planted = 0;
  for (int f = 2; f <= t.last; ++f) {
    char frame[16];
    std::snprintf(frame, sizeof frame, "%04d", f);
    for (const std::string& n :
         {"out/composite/.frame_" + std::string(frame) + tag + ".png",
          "out/layered/.frame_" + std::string(frame) + tag + ".exr",
          "out/layers/base/.base_" + std::string(frame) + tag + ".exr",
          "out/layers/base/.base_" + std::string(frame) + tag + ".png",
          "out/layers/outline/.outline_" + std::string(frame) + tag + ".png"})
      planted += ::symlink((dir_ / "victim.txt").c_str(), (dir_ / n).c_str()) == 0;
  }
  int status = 0;
  const bool running = ::waitpid(pid, &status, WNOHANG) == 0;
  if (running) ::waitpid(pid, &status, 0);
  ASSERT_TRUE(running) << "the run finished before the links were planted";
  EXPECT_EQ(planted, 5 * (t.last - 1));
  ASSERT_TRUE(WIFEXITED(status)) << slurp(err_path);
  EXPECT_EQ(WEXITSTATUS(status), 0) << slurp(err_path);
  // (Compared as booleans: an overwritten victim holds a whole PNG.)
  EXPECT_TRUE(slurp(dir_ / "victim.txt") == "precious\n") << "a planted link was written through";
  EXPECT_TRUE(slurp(dir_ / "victim2.txt") == "also precious\n");
  EXPECT_FALSE(fs::is_symlink(dir_ / "out/composite/frame_0005.png"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out/composite/frame_0005.png"));
}

TEST_F(OutputSafety, PreviewsReplaceALinkAtTheirNameAndLeaveNoTemporary) {
  if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0) GTEST_SKIP() << "no ffmpeg on PATH";
  ShotText t;
  t.sheet = true;
  t.mp4 = true;
  write_shot(t);
  fs::create_directories(dir_ / "out");
  write_text(dir_ / "victim.txt", "precious\n");
  fs::create_symlink(dir_ / "victim.txt", dir_ / "out/preview.mp4");
  fs::create_symlink(dir_ / "victim.txt", dir_ / "out/contact_sheet.png");
  expect_ok(emaki("run " + p("shot.toml")));
  EXPECT_TRUE(slurp(dir_ / "victim.txt") == "precious\n");
  EXPECT_FALSE(fs::is_symlink(dir_ / "out/preview.mp4"));
  EXPECT_GT(fs::file_size(dir_ / "out/preview.mp4"), 0u);
  EXPECT_FALSE(fs::is_symlink(dir_ / "out/contact_sheet.png"));
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "out"))
    EXPECT_EQ(e.path().filename().string().find(".emaki-tmp-"), std::string::npos) << e.path();
}

// emaki starts itself again with glibc's huge-page tunable where the kernel's THP mode is
// "madvise" (apps/emaki/huge_pages.h); what it runs inherits that environment, so a stand-in
// ffmpeg early on PATH shows whether the restart happened.
TEST_F(OutputSafety, RunsWithHugePagesWhereTheKernelTakesAdvice) {
  if (std::getenv("GLIBC_TUNABLES")) GTEST_SKIP() << "GLIBC_TUNABLES set by the caller";
  const std::string mode = slurp("/sys/kernel/mm/transparent_hugepage/enabled");
  ShotText t;
  t.last = 0;
  t.mp4 = true;
  write_shot(t);
  fs::create_directories(dir_ / "bin");
  // It writes its output (the last argument): an empty MP4 is refused as a failed write.
  write_text(dir_ / "bin/ffmpeg", "#!/bin/sh\nprintf '%s' \"$GLIBC_TUNABLES\" > '" + p("tunables") +
                                      "'\nfor out; do :; done\nprintf stand-in > \"$out\"\n");
  fs::permissions(dir_ / "bin/ffmpeg", fs::perms::owner_all);
  test::CliOptions o;
  o.cwd = dir_;
  o.env = {"PATH=" + p("bin") + ":" + std::getenv("PATH")};
  expect_ok(test::run_cli(EMAKI_BINARY, {"run", p("shot.toml")}, o));
  const bool advised = mode.find("[madvise]") != std::string::npos;
  EXPECT_EQ(slurp(dir_ / "tunables"), advised ? "glibc.malloc.hugetlb=1" : "") << mode;
}

// ---- the output-folder lock ----

TEST_F(OutputSafety, SecondRunOnTheSameFolderNamesTheHolder) {
  ShotText t;
  t.last = 7;
  t.w = 64;
  t.h = 48;
  write_shot(t);
  const std::string err_path = p("first_stderr.txt");
  const pid_t first = test::spawn_cli(EMAKI_BINARY, {"run", p("shot.toml")}, err_path);
  ASSERT_GE(first, 0);
  // The holder writes its pid into the lock file once it holds the lock.
  const fs::path lock = dir_ / "out/.emaki.lock";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (slurp(lock).find("pid") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_NE(slurp(lock).find("pid"), std::string::npos);
  // Held still while the others try, so a fast machine cannot finish it first (8 small frames
  // took 1.5 s); a stopped child is not reported by waitpid without WUNTRACED.
  ASSERT_EQ(::kill(first, SIGSTOP), 0);

  const test::CliResult second = emaki("run " + p("shot.toml"));
  const test::CliResult composite = emaki("composite " + p("shot.toml"));
  int status = 0;
  const bool first_still_running = ::waitpid(first, &status, WNOHANG) == 0;
  ::kill(first, SIGCONT);
  if (first_still_running) ::waitpid(first, &status, 0);
  ASSERT_TRUE(first_still_running) << "the first run finished before the second started";

  expect_error(second, ".emaki.lock");
  EXPECT_NE(second.err.find("pid " + std::to_string(first)), std::string::npos) << second.err;
  EXPECT_NE(second.err.find("since"), std::string::npos) << second.err;
  expect_error(composite, ".emaki.lock");
  // The first run was not disturbed.
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << slurp(err_path);
  for (int f = 0; f <= t.last; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "out/composite/frame_%04d.png", f);
    EXPECT_TRUE(fs::is_regular_file(dir_ / name)) << name;
  }
}

TEST_F(OutputSafety, LockLeftByAKilledRunDoesNotBlock) {
  write_shot(ShotText{});
  fs::create_directories(dir_ / "out");
  write_text(dir_ / "out/.emaki.lock", "pid 999999 on elsewhere since 2020-01-01 00:00:00 UTC\n");
  expect_ok(emaki("run " + p("shot.toml")));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out/composite/frame_0001.png"));
}

// ---- resume against changed settings ----

TEST_F(OutputSafety, ResumeAfterASizeChangeRedoesEveryFrame) {
  ShotText t;
  t.last = 2;
  t.sheet = true;
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  t.w = 40;
  t.h = 30;
  write_shot(t);
  const test::CliResult r = emaki("run " + p("shot.toml"));
  expect_ok(r);
  EXPECT_NE(r.err.find("6 layer-frames synthesized, 0 already finished"), std::string::npos)
      << r.err;
  expect_all_sized(dir_ / "out", ".png", 40, 30);
  expect_all_sized(dir_ / "out", ".exr", 40, 30);
  // Three 40x30 thumbnails in a row, 4-pixel gaps.
  const Image<float> sheet = io::read_image_float(p("out/contact_sheet.png"));
  EXPECT_EQ(sheet.width(), 3 * 40 + 4 * 4);
  EXPECT_EQ(sheet.height(), 30 + 2 * 4);
  // And once more: everything is finished now.
  const test::CliResult again = emaki("run " + p("shot.toml"));
  expect_ok(again);
  EXPECT_NE(again.err.find("0 layer-frames synthesized, 6 already finished"), std::string::npos)
      << again.err;
}

TEST_F(OutputSafety, SingleColourToggleRedoesTheLayer) {
  ShotText t;
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  EXPECT_EQ(io::read_image_float(p("out/layers/base/base_0001.exr")).channels(), 1 + 1);
  t.base_extra = "single_colour = false";
  write_shot(t);
  const test::CliResult r = emaki("run " + p("shot.toml"));
  expect_ok(r);
  EXPECT_NE(r.err.find("2 layer-frames synthesized, 2 already finished"), std::string::npos)
      << r.err;
  EXPECT_EQ(io::read_image_float(p("out/layers/base/base_0001.exr")).channels(), 3 + 1);
  // `composite` and `qa flicker` read the redone layer without complaint.
  expect_ok(emaki("composite " + p("shot.toml")));
  expect_ok(emaki("qa flicker " + p("shot.toml") + " --layer base"));
  t.base_extra = "";
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  EXPECT_EQ(io::read_image_float(p("out/layers/base/base_0001.exr")).channels(), 1 + 1);
}

// The confidence decides the temporal frames: turning it off redoes the layer's temporal frame,
// and `qa ghost` measures the finished layer either way.
TEST_F(OutputSafety, TemporalConfidenceToggleRedoesTheLayer) {
  ShotText t;
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  const test::CliResult ghost = emaki("qa ghost " + p("shot.toml") + " --layer base");
  expect_ok(ghost);
  EXPECT_NE(ghost.out.find("\"ghost_share\": "), std::string::npos) << ghost.out;
  t.base_extra = "temporal_confidence = false";
  write_shot(t);
  const test::CliResult r = emaki("run " + p("shot.toml"));
  expect_ok(r);
  EXPECT_NE(r.err.find("2 layer-frames synthesized, 2 already finished"), std::string::npos)
      << r.err;
  expect_ok(emaki("qa ghost " + p("shot.toml") + " --layer base"));
}

TEST_F(OutputSafety, QaFlickerAfterAResizeSaysToRunAgain) {
  ShotText t;
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  t.w = 40;
  t.h = 30;
  write_shot(t);
  const test::CliResult r = emaki("qa flicker " + p("shot.toml") + " --layer base");
  expect_error(r, "layers/base: was made with other settings (size was 32x24, now 40x30)");
  EXPECT_NE(r.err.find("emaki run"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
}

TEST_F(OutputSafety, CompositeAfterAResizeSaysToRunAgain) {
  ShotText t;
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  t.w = 40;
  t.h = 30;
  write_shot(t);
  const test::CliResult r = emaki("composite " + p("shot.toml"));
  expect_error(r, "layers/base: was made with other settings");
  EXPECT_NE(r.err.find("emaki run"), std::string::npos) << r.err;
  // Nothing was rewritten: the old frames are still the old size.
  EXPECT_EQ(io::read_image_float(p("out/composite/frame_0000.png")).width(), 32);
}

TEST_F(OutputSafety, ALayerFileReplacedOnDiskIsAnErrorNotAnAbort) {
  write_shot(ShotText{});
  expect_ok(emaki("run " + p("shot.toml")));
  // Same name, other size (the manifest still matches: only the file changed).
  Image<float> wrong(7, 5, 2);
  io::WriteOptions wo;
  wo.format = io::SampleFormat::kFloat;
  wo.channel_names = {"Y", "A"};
  io::write_image(p("out/layers/base/base_0000.exr"), wrong.cview(), wo);
  expect_error(emaki("composite " + p("shot.toml")), "base_0000.exr: is 7x5 with 2 channels");
  expect_error(emaki("qa flicker " + p("shot.toml") + " --layer base"),
               "base_0000.exr: is 7x5 with 2 channels");
}

TEST_F(OutputSafety, AComposedFrameReplacedOnDiskStopsTheContactSheet) {
  ShotText t;
  t.sheet = true;
  write_shot(t);
  expect_ok(emaki("run " + p("shot.toml")));
  Image<float> wrong(9, 400, 1);
  io::write_image(p("out/composite/frame_0001.png"), wrong.cview());
  expect_error(emaki("run " + p("shot.toml")), "frame_0001.png: is 9x400, the shot makes 32x24");
}

}  // namespace
