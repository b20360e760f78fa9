// End-to-end tests of `emaki run` / `emaki composite` on tiny shots: bad shot files (one-line
// error naming the key path, non-zero exit, nothing written), re-colouring without synthesis,
// and resuming a killed run to bit-identical frames.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>

#include "core/image.h"
#include "io/image_io.h"
#include "store/field_file.h"
#include "store/file_store.h"
#include "tests/small_painting.h"
#include "tests/test_dir.h"

extern char** environ;

namespace fs = std::filesystem;
using namespace emaki;

namespace {

const std::string kData = EMAKI_TEST_DATA;

struct RunResult {
  int exit_code;
  std::string err;
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Bit-identical pixels (EXR headers carry a creation date, so files are compared by content).
bool same_pixels(const fs::path& a, const fs::path& b) {
  const Image<float> x = io::read_image_float(a.string()), y = io::read_image_float(b.string());
  if (x.width() != y.width() || x.height() != y.height() || x.channels() != y.channels())
    return false;
  for (int r = 0; r < x.height(); ++r)
    if (std::memcmp(x.row(r), y.row(r), sizeof(float) * x.width() * x.channels()) != 0)
      return false;
  return true;
}

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// The base shot: Fox walking at 64x48, a small copy of the StyLit painting as a MatCap-like
// exemplar, base + outline layers with temporal on.
const char* kShot = R"(threads = 2
[source]
scene = "@DATA@/scenes/Fox.glb"
clip = "Walk"
frames = [0, @LAST@]
size = [64, 48]
aa = 1
[source.camera]
orbit = 15
[source.light]
direction = [0.3, 0.9, -0.3]

[exemplars.sphere]
painting = "painting.png"
sphere = [50.7, 41.2, 20.2]
elevation = 20
light = [0.3, 0.9, -0.3]
aa = 1

[layers.base]
kind = "base"
exemplar = "sphere"
patch_size = 5
@BASE_EXTRA@

[layers.outline]
kind = "outline"
exemplar = "sphere"

[compositing]
paper = "@DATA@/papers/roughpaper.png"

[outputs]
folder = "out"
mp4 = false
contact_sheet = false
)";

class ShotCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_test_dir("emaki_shot");
    test::write_small_painting(kData + "/stylit/source_style.png", p("painting.png"));
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string p(const std::string& name) const { return (dir_ / name).string(); }

  std::string shot_text(int last = 2, const std::string& base_extra = "") const {
    std::string s = kShot;
    s = std::regex_replace(s, std::regex("@DATA@"), kData);
    s = std::regex_replace(s, std::regex("@LAST@"), std::to_string(last));
    s = std::regex_replace(s, std::regex("@BASE_EXTRA@"), base_extra);
    return s;
  }
  void write_shot(const std::string& text, const std::string& name = "shot.toml") const {
    std::ofstream(p(name)) << text;
  }
  RunResult emaki(const std::string& args) const {
    const std::string err = p("stderr.txt");
    const std::string cmd = "cd " + dir_.string() + " && " + EMAKI_BINARY + " " + args + " 2>" +
                            err + " >" + p("stdout.txt");
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(err)};
  }

  // Replaces the first occurrence of `from` in the base shot and expects `emaki run` to fail
  // with one line that names `key` and to leave no output folder.
  void expect_bad(const std::string& text, const std::string& key) {
    fs::remove_all(dir_ / "out");
    write_shot(text);
    const RunResult r = emaki("run shot.toml");
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(key + ":"), std::string::npos)
        << "expected key " << key << " in: " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out")) << "output written for: " << r.err;
  }
  std::string replaced(const std::string& from, const std::string& to) const {
    std::string s = shot_text();
    const std::size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  }

  fs::path dir_;
};

// ---- bad shot files ----

TEST_F(ShotCli, UnknownKeySuggestsTheClosest) {
  expect_bad(replaced("patch_size = 5", "patch_sise = 5"), "layers.base.patch_sise");
  EXPECT_NE(emaki("run shot.toml").err.find("did you mean 'patch_size'"), std::string::npos);
}

TEST_F(ShotCli, UnknownSectionSuggestsTheClosest) {
  expect_bad(replaced("[outputs]", "[ouputs]"), "ouputs");
  EXPECT_NE(emaki("run shot.toml").err.find("did you mean 'outputs'"), std::string::npos);
}

TEST_F(ShotCli, WrongTypeNamesTheExpectedType) {
  expect_bad(replaced("patch_size = 5", "patch_size = \"five\""), "layers.base.patch_size");
  EXPECT_NE(emaki("run shot.toml").err.find("expected an integer, got a string"),
            std::string::npos);
}

TEST_F(ShotCli, FramesOfTheWrongType) {
  expect_bad(replaced("frames = [0, 2]", "frames = \"0-2\""), "source.frames");
}

TEST_F(ShotCli, MissingExemplarFile) {
  expect_bad(replaced("painting.png", "no_such_painting.png"), "exemplars.sphere.painting");
}

TEST_F(ShotCli, EmptyFrameRange) {
  expect_bad(replaced("frames = [0, 2]", "frames = []"), "source.frames");
}

TEST_F(ShotCli, ReversedFrameRange) {
  expect_bad(replaced("frames = [0, 2]", "frames = [5, 2]"), "source.frames");
  EXPECT_NE(emaki("run shot.toml").err.find("reversed"), std::string::npos);
}

TEST_F(ShotCli, LayerReferringToAnUndefinedExemplar) {
  expect_bad(replaced("exemplar = \"sphere\"\npatch_size", "exemplar = \"spere\"\npatch_size"),
             "layers.base.exemplar");
  EXPECT_NE(emaki("run shot.toml").err.find("did you mean 'sphere'"), std::string::npos);
}

TEST_F(ShotCli, UnwritableOutputFolder) {
  expect_bad(replaced("folder = \"out\"", "folder = \"/proc/emaki_out\""), "outputs.folder");
}

TEST_F(ShotCli, UnknownGuidePass) {
  expect_bad(shot_text(2, "guides = { normale = 1.0 }"), "layers.base.guides.normale");
  EXPECT_NE(emaki("run shot.toml").err.find("did you mean 'normal'"), std::string::npos);
}

TEST_F(ShotCli, UnknownBlendMode) {
  expect_bad(shot_text(2, "blend = \"multiplly\""), "layers.base.blend");
  EXPECT_NE(emaki("run shot.toml").err.find("did you mean 'multiply'"), std::string::npos);
}

TEST_F(ShotCli, EvenPatchSize) {
  expect_bad(replaced("patch_size = 5", "patch_size = 4"), "layers.base.patch_size");
}

TEST_F(ShotCli, MissingSceneFile) {
  expect_bad(replaced("scenes/Fox.glb", "scenes/NoFox.glb"), "source.scene");
}

TEST_F(ShotCli, SyntaxErrorNamesFileLineAndColumn) {
  expect_bad(replaced("frames = [0, 2]", "frames = [0, "), "shot.toml:6");
}

TEST_F(ShotCli, ClipNotInTheScene) {
  expect_bad(replaced("clip = \"Walk\"", "clip = \"Dance\""), "source.clip");
}

TEST_F(ShotCli, FrameRangePastTheClip) {
  expect_bad(replaced("frames = [0, 2]", "frames = [0, 5000]"), "source.frames");
}

TEST_F(ShotCli, ColourOutOfRange) {
  expect_bad(shot_text(2, "color = [2, 0, 0]"), "layers.base.color");
}

TEST_F(ShotCli, SceneAndSequenceTogether) {
  expect_bad(replaced("clip = \"Walk\"", "sequence = \"r/frame_%04d.exr\""), "source");
}

TEST_F(ShotCli, MissingOutputsSection) {
  std::string s = shot_text();
  s = s.substr(0, s.find("[outputs]"));
  expect_bad(s, "outputs");
}

TEST_F(ShotCli, KeyframeExemplarAndItsPassesOfDifferentSizes) {
  // A 64x48 pass file from `emaki render` next to the 100x76 painting.
  ASSERT_EQ(
      emaki("render " + kData + "/scenes/Fox.glb --frames 0-0 --size 64x48 --aa 1 --out renders")
          .exit_code,
      0);
  std::string exr;
  for (const auto& e : fs::directory_iterator(dir_ / "renders"))
    if (e.path().extension() == ".exr") exr = e.path().filename().string();
  ASSERT_FALSE(exr.empty());
  std::string s = shot_text();
  const std::size_t a = s.find("[exemplars.sphere]"), b = s.find("[layers.base]");
  s.replace(
      a, b - a,
      "[exemplars.sphere]\nkind = \"keyframe\"\npainting = \"painting.png\"\npasses = \"renders/" +
          exr + "\"\n\n");
  expect_bad(s, "exemplars.sphere.passes");
  EXPECT_NE(emaki("run shot.toml").err.find("64x48"), std::string::npos);
}

TEST_F(ShotCli, SequencePassChannelNotInTheExr) {
  ASSERT_EQ(
      emaki("render " + kData + "/scenes/Fox.glb --frames 0-2 --size 64x48 --aa 1 --out renders")
          .exit_code,
      0);
  std::string exr;
  for (const auto& e : fs::directory_iterator(dir_ / "renders"))
    if (e.path().extension() == ".exr") exr = e.path().filename().string();
  ASSERT_FALSE(exr.empty());
  // frame_0000.exr -> frame_%04d.exr
  const std::string pattern = std::regex_replace(exr, std::regex("[0-9]{4}"), "%04d");
  std::string s = shot_text();
  const std::size_t a = s.find("scene = "), b = s.find("[exemplars.sphere]");
  s.replace(a, b - a,
            "sequence = \"renders/" + pattern +
                "\"\nframes = [0, 2]\n[source.channels]\nnormal = [\"N.X\", \"N.Y\", \"N.Z\"]\n\n");
  expect_bad(s, "source.channels.normal");
}

TEST_F(ShotCli, SequenceSourceAndKeyframeExemplarRun) {
  ASSERT_EQ(emaki("render " + kData +
                  "/scenes/Fox.glb --clip Walk --frames 0-2 --size 64x48 --aa 1 --out renders")
                .exit_code,
            0);
  std::string exr;
  for (const auto& e : fs::directory_iterator(dir_ / "renders"))
    if (e.path().extension() == ".exr" &&
        e.path().filename().string().find("0000") != std::string::npos)
      exr = e.path().filename().string();
  ASSERT_FALSE(exr.empty());
  const std::string pattern = std::regex_replace(exr, std::regex("[0-9]{4}"), "%04d");
  // A 64x48 "painted keyframe": the painting squeezed to the frame's size.
  const Image<float> painting = io::read_image_float(p("painting.png"));
  Image<float> key(64, 48, 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) key(x, y, c) = painting(x * 100 / 64, y * 76 / 48, c);
  io::write_image(p("key.png"), key.cview());
  std::string s = shot_text();
  const std::size_t a = s.find("scene = "), b = s.find("[layers.base]");
  s.replace(a, b - a,
            "sequence = \"renders/" + pattern +
                "\"\nframes = [0, 2]\n\n[exemplars.sphere]\n"
                "kind = \"keyframe\"\npainting = \"key.png\"\npasses = \"renders/" +
                exr + "\"\n\n");
  write_shot(s);
  const RunResult r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir_ / "out/composite/frame_0002.png"));
  const Image<float> base = io::read_image_float(p("out/layers/base/base_0002.exr"));
  EXPECT_EQ(base.width(), 64);
  EXPECT_EQ(base.height(), 48);
}

// --timings: a line per stage in the farm's task kinds, then their total; the outputs are those
// of a run without it.
TEST_F(ShotCli, TimingsNameEveryStageAndChangeNoOutput) {
  write_shot(shot_text(1));
  RunResult r = emaki("run shot.toml --timings");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  double sum = 0.0, total = 0.0;
  for (const std::string s : {"prepare", "passes", "layers", "composite", "previews", "total"}) {
    std::smatch m;
    const std::regex line("emaki run: " + s + " +[0-9]+\\.[0-9]+ +([0-9]+\\.[0-9]+)\n");
    ASSERT_TRUE(std::regex_search(r.err, m, line)) << s << " in: " << r.err;
    (s == "total" ? total : sum) += std::stod(m[1].str());
  }
  EXPECT_NEAR(total, sum, 0.03);  // the rows, each rounded to 0.01
  EXPECT_GT(total, 0.0);
  const std::string comp = slurp(dir_ / "out/composite/frame_0001.png");
  fs::remove_all(dir_ / "out");
  r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("emaki run: total"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(dir_ / "out/composite/frame_0001.png"), comp);
}

// ---- re-colouring ----

TEST_F(ShotCli, CompositeRecoloursWithoutSynthesizing) {
  write_shot(shot_text(1));
  RunResult r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path layer = dir_ / "out/layers/base/base_0001.exr";
  const fs::path comp = dir_ / "out/composite/frame_0001.png";
  ASSERT_TRUE(fs::exists(layer));
  ASSERT_TRUE(fs::exists(comp));
  // The layered EXR holds every pass and every layer under distinct names.
  const std::vector<std::string> ch = io::list_channels(p("out/layered/frame_0001.exr"));
  for (const char* name :
       {"normal.X", "outline.Y", "layer_base.Y", "layer_base.A", "layer_outline.Y", "composite.R"})
    EXPECT_NE(std::find(ch.begin(), ch.end(), name), ch.end()) << name;
  EXPECT_EQ(ch.size(), 24u + 2 + 2 + 3);
  const std::string layer_before = slurp(layer), comp_before = slurp(comp);
  const auto layer_time = fs::last_write_time(layer);

  write_shot(shot_text(1, "color = [1.0, 0.2, 0.1]\nblend = \"multiply\""));
  r = emaki("composite shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(layer), layer_before);
  EXPECT_EQ(fs::last_write_time(layer), layer_time);
  const std::string comp_after = slurp(comp);
  EXPECT_NE(comp_after, comp_before);
  // The new colour shows: where the base layer covers, red now dominates green.
  const Image<float> before = io::read_image_float(p("out/layers/base/base_0001.exr"));
  const Image<float> after = io::read_image_float(comp.string());
  double red = 0, green = 0;
  for (int y = 0; y < after.height(); ++y)
    for (int x = 0; x < after.width(); ++x)
      if (before(x, y, 1) > 0.5f) red += after(x, y, 0), green += after(x, y, 1);
  EXPECT_GT(red, 1.5 * green);
  // And a second `emaki run` finds everything finished: nothing is synthesized.
  r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(" 0 layer-frames synthesized"), std::string::npos) << r.err;
}

// ---- resume ----

// The field kept beside each temporal layer frame (the next frame's warm start) is read as
// hostile input: a truncated, resized, garbled or stale one never breaks a resumed run (the
// frame runs the whole pyramid instead); junk inside a well-formed one is drawn at random where
// it leaves the exemplar. The intact field gives the frame back bit for bit.
TEST_F(ShotCli, DamagedWarmStartFieldsNeverBreakAResume) {
  write_shot(shot_text(2));
  RunResult r = emaki("run shot.toml --frames 0-1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path field = dir_ / "out/layers/base/.base_0001.nnf";
  const fs::path frame = dir_ / "out/layers/base/base_0002.exr";
  ASSERT_TRUE(fs::is_regular_file(field));
  // Every finished frame's field is kept, compressed.
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out/layers/base/.base_0000.nnf"));
  const std::string good = slurp(field);
  r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(field));
  ASSERT_TRUE(fs::is_regular_file(dir_ / "out/layers/base/.base_0002.nnf"));
  fs::copy_file(frame, dir_ / "ref.exr");
  ASSERT_GT(good.size(), 40u);
  ASSERT_LT(good.size(), 32u + 64u * 48u * 8u / 2);
  uint64_t digest = 0;
  std::memcpy(&digest, good.data() + 24, sizeof digest);
  // Junk coordinates in a well-formed file: what an older or foreign build could have written.
  Image<int32_t> junk_field(64, 48, 2);
  for (int y = 0; y < 48; ++y)
    for (int i = 0; i < 64 * 2; ++i)
      junk_field.row(y)[i] = int32_t(uint32_t(y * 977 + i * 131 + 7));
  const std::string junk = io::encode_field(1, junk_field.cview(), digest);
  std::string magic = good, other = good, flipped = good, version1 = good.substr(0, 32);
  magic[0] = 'X';
  other[24] ^= 1;  // the digest of another value
  flipped[good.size() / 2] ^= 0x10;
  version1[8] = 1;  // the uncompressed format of before
  version1 += std::string(64 * 48 * 8, '\0');
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"truncated", good.substr(0, good.size() - 4)},
      {"header only", good.substr(0, 32)},
      {"empty", ""},
      {"longer", good + "xxxxxxxx"},
      {"bad magic", magic},
      {"stale", other},
      {"junk inside", junk},
      {"bit flipped", flipped},
      {"uncompressed", version1},
      {"intact", good}};
  for (const auto& [what, bytes] : damaged) {
    std::ofstream(field, std::ios::binary | std::ios::trunc) << bytes;
    fs::remove(frame);
    r = emaki("run shot.toml");
    ASSERT_EQ(r.exit_code, 0) << what << ": " << r.err;
    ASSERT_TRUE(fs::is_regular_file(frame)) << what;
    if (what == "stale") {
      EXPECT_FALSE(same_pixels(frame, dir_ / "ref.exr")) << what;
    } else if (what == "intact") {
      EXPECT_TRUE(same_pixels(frame, dir_ / "ref.exr")) << what;
    }
  }
}

// Every frame's field is kept: `emaki run --force --frames A-B` inside a finished shot starts
// frame A from frame A-1's field, as the uninterrupted run did, and gives its frames back bit
// for bit (also with another thread count: fields are written byte-identical by 1 and 2
// threads). When a re-run frame B comes out different (here: frame 2's field damaged, so frame
// 3 runs the whole pyramid), one warning line names the layer and the finished frames after B
// that were made from the old frame B.
TEST_F(ShotCli, ForcedRangeInsideAFinishedShotIsBitIdentical) {
  write_shot(shot_text(6));
  RunResult r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  fs::copy(dir_ / "out", dir_ / "out_ref", fs::copy_options::recursive);
  // Names inside an output folder, as the store writes them.
  const io::OutputPaths in_folder{"."};
  auto layer = [&](const std::string& l, int f) { return in_folder.layer_exr(l, f); };
  auto field = [&](const std::string& l, int f) { return in_folder.layer_field(l, f); };
  auto same = [&](const std::string& file) {
    return same_pixels(dir_ / "out" / file, dir_ / "out_ref" / file);
  };
  r = emaki("run shot.toml --force --frames 3-4 --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(" 4 layer-frames synthesized"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  for (int f = 0; f <= 6; ++f)
    for (const char* l : {"base", "outline"}) {
      EXPECT_TRUE(same(layer(l, f))) << layer(l, f);
      EXPECT_TRUE(slurp(dir_ / "out" / field(l, f)) == slurp(dir_ / "out_ref" / field(l, f)))
          << field(l, f);
    }
  // Frame 3 of the base layer from the whole pyramid: frames 5-6 were made from the old frame 4.
  std::ofstream(dir_ / "out" / field("base", 2), std::ios::trunc) << "damaged";
  r = emaki("run shot.toml --force --frames 3-4");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(same(layer("base", 4)));
  EXPECT_TRUE(same(layer("outline", 4)));
  const std::size_t at = r.err.find("warning");
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("warning", at + 1), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("warning: layer base: frames 5-6 were made from frame 4"), std::string::npos)
      << r.err;
  // One stale frame is named as one frame, and the command given redoes just it.
  std::ofstream(dir_ / "out" / field("base", 3), std::ios::trunc) << "damaged";
  r = emaki("run shot.toml --force --frames 4-5");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: layer base: frame 6 was made from frame 5 "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--force --frames 6 --layers base` redoes it"), std::string::npos) << r.err;
}

// With temporal_fields = "last" a run keeps one warm-start field per temporal layer, the last
// finished frame's, and a run that stopped part-way still resumes to the same frames as an
// uninterrupted one.
TEST_F(ShotCli, KeepingOnlyTheLastFieldStillResumesExactly) {
  auto last_only = [&](const std::string& folder) {
    std::string s = shot_text(5, "temporal_fields = \"last\"");
    s.replace(s.find("[layers.outline]"), 16, "[layers.outline]\ntemporal_fields = \"last\"");
    s.replace(s.find("folder = \"out\""), 14, "folder = \"" + folder + "\"");
    return s;
  };
  write_shot(last_only("out_ref"), "ref.toml");
  RunResult r = emaki("run ref.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  write_shot(last_only("out"));
  r = emaki("run shot.toml --frames 0-2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(" 6 layer-frames synthesized, 6 already finished"), std::string::npos)
      << r.err;
  const io::OutputPaths in_folder{"."};
  for (const char* l : {"base", "outline"})
    for (int f = 0; f <= 5; ++f) {
      const std::string exr = in_folder.layer_exr(l, f), field = in_folder.layer_field(l, f);
      EXPECT_TRUE(same_pixels(dir_ / "out" / exr, dir_ / "out_ref" / exr)) << exr;
      EXPECT_EQ(fs::exists(dir_ / "out" / field), f == 5) << field;
      EXPECT_EQ(fs::exists(dir_ / "out_ref" / field), f == 5) << field;
    }
  // A forced range inside the finished shot has no field before it: its first frame runs the
  // whole pyramid, and the run still succeeds. The field kept is still the last frame's.
  r = emaki("run shot.toml --force --frames 3-4");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int f = 0; f <= 5; ++f)
    EXPECT_EQ(fs::exists(dir_ / "out" / in_folder.layer_field("base", f)), f == 5) << f;
}

// Switching a finished shot from temporal_fields = "every" to "last" drops the older fields at
// the next run, also when it has no frame left to synthesize.
TEST_F(ShotCli, SwitchingToTheLastFieldDropsTheOlderOnes) {
  write_shot(shot_text(3));
  RunResult r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::OutputPaths in_folder{"."};
  for (int f = 0; f <= 3; ++f)
    ASSERT_TRUE(fs::exists(dir_ / "out" / in_folder.layer_field("base", f)));
  write_shot(shot_text(3, "temporal_fields = \"last\""));
  r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find(" 0 layer-frames synthesized"), std::string::npos) << r.err;
  for (int f = 0; f <= 3; ++f) {
    EXPECT_EQ(fs::exists(dir_ / "out" / in_folder.layer_field("base", f)), f == 3) << f;
    EXPECT_TRUE(fs::exists(dir_ / "out" / in_folder.layer_exr("base", f))) << f;
  }
  // The outline layer keeps every field.
  for (int f = 0; f <= 3; ++f)
    EXPECT_TRUE(fs::exists(dir_ / "out" / in_folder.layer_field("outline", f))) << f;
}

TEST_F(ShotCli, KilledRunResumesToBitIdenticalFrames) {
  const int last = 7;
  write_shot(shot_text(last));
  // Uninterrupted, into out_ref.
  {
    std::string s = shot_text(last);
    s.replace(s.find("folder = \"out\""), 14, "folder = \"out_ref\"");
    write_shot(s, "ref.toml");
  }
  RunResult r = emaki("run ref.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // Killed once frame 2 of the base layer is finished.
  pid_t pid = 0;
  std::vector<std::string> args = {EMAKI_BINARY, "run", p("shot.toml")};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
  ASSERT_EQ(posix_spawn(&pid, EMAKI_BINARY, &fa, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&fa);
  const fs::path marker = dir_ / "out/layers/base/base_0002.exr";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(marker) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before it could be killed";
  ASSERT_FALSE(fs::exists(dir_ / "out/composite" / "frame_0007.png"));

  r = emaki("run shot.toml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find(" 0 layer-frames synthesized"), std::string::npos) << r.err;
  const io::OutputPaths in_folder{"."};  // names inside an output folder, as the store writes them
  for (int f = 0; f <= last; ++f) {
    const std::string composite = in_folder.composite_png(f);
    EXPECT_TRUE(same_pixels(dir_ / "out" / composite, dir_ / "out_ref" / composite)) << composite;
    for (const char* layer : {"base", "outline"}) {
      const std::string exr = in_folder.layer_exr(layer, f);
      EXPECT_TRUE(same_pixels(dir_ / "out" / exr, dir_ / "out_ref" / exr)) << exr;
    }
  }
  // No temporary file is left behind.
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "out"))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

}  // namespace
