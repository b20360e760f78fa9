// Hostile shot files and render options (issue 9): every bad input below must end in exit 1,
// no signal, within the 60 s / 2 GiB bound of tests/cli_run.h, with one stderr line naming the
// key path / option / file, and no output folder. The small reproducers also live in
// tests/data/hostile/shot/ (replayed by the `shot` fuzz target); large ones are made here.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "cli_run.h"
#include "core/error.h"
#include "core/image.h"
#include "io/image_io.h"
#include "render/passes.h"
#include "shot/api.h"
#include "shot/inputs.h"
#include "store/frame_sequence.h"

namespace fs = std::filesystem;
using emaki::test::CliResult;
using emaki::test::count_lines;
using emaki::test::run_cli;

namespace {

const std::string kData = EMAKI_TEST_DATA;
const std::string kHostile = EMAKI_HOSTILE;

// A tiny valid shot; each @NAME@ is a slot a case fills (defaults in Slots below).
const char* kShot = R"(threads = 1
@TOP@
[source]
@SCENE@
frames = @FRAMES@
@SIZE@
aa = 1
@SOURCE@
[source.camera]
@CAMERA@
[source.light]
direction = [0.3, 0.9, -0.3]
@LIGHT@
[source.ground]
@GROUND@
[exemplars.sphere]
painting = "@DATA@/stylit/source_style.png"
sphere = [50.7, 41.2, 20.2]
@EXEMPLAR@
[layers.base]
kind = "base"
exemplar = "sphere"
@LAYER@
[compositing]
@COMPOSITING@
[outputs]
folder = "out"
mp4 = false
contact_sheet = false
)";

using Slots = std::map<std::string, std::string>;

std::string shot_text(const Slots& over) {
  Slots slots = {
      {"TOP", ""},          {"SCENE", "scene = \"@DATA@/scenes/Fox.glb\"\nclip = \"Walk\""},
      {"FRAMES", "[0, 2]"}, {"SIZE", "size = [64, 48]"},
      {"SOURCE", ""},       {"CAMERA", ""},
      {"LIGHT", ""},        {"GROUND", ""},
      {"EXEMPLAR", ""},     {"LAYER", ""},
      {"COMPOSITING", ""}};
  for (const auto& [k, v] : over) slots[k] = v;
  std::string s = kShot;
  for (const auto& [k, v] : slots) {
    const std::string tag = "@" + k + "@";
    s.replace(s.find(tag), tag.size(), v);
  }
  return std::regex_replace(s, std::regex("@DATA@"), kData);
}

class HostileShot : public ::testing::Test {
 protected:
  std::string p(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(p(name), std::ios::binary) << text;
  }

  CliResult emaki(const std::vector<std::string>& args) const {
    emaki::test::CliOptions o;
    o.cwd = dir_;
    return run_cli(EMAKI_BINARY, args, o);
  }

  // The contract of every case: exit 1, no signal, in time, one short line that names
  // `subject`, and nothing written to the output folder.
  void expect_refused(const CliResult& r, const std::string& command, const std::string& subject,
                      const std::string& out = "out") const {
    EXPECT_FALSE(r.timed_out) << subject;
    EXPECT_EQ(r.signal, 0) << subject << ": " << r.err.substr(0, 2000);
    EXPECT_EQ(r.exit_code, 1) << subject << ": " << r.err.substr(0, 2000);
    EXPECT_EQ(count_lines(r.err), 1) << r.err.substr(0, 2000);
    const std::string prefix = "emaki " + command + ": error: " + subject + ":";
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u)
        << "expected '" << prefix << "' in: " << r.err.substr(0, 2000);
    // Echoed values are capped (80 bytes each): no line approaches the size of the input.
    EXPECT_LT(r.err.size(), 600u) << r.err.substr(0, 2000);
    EXPECT_FALSE(fs::exists(dir_ / out)) << "output folder left by: " << r.err;
  }

  void expect_bad_shot(const std::string& text, const std::string& subject,
                       std::vector<std::string> extra_args = {}) const {
    write("shot.toml", text);
    std::vector<std::string> args = {"run", "shot.toml"};
    args.insert(args.end(), extra_args.begin(), extra_args.end());
    expect_refused(emaki(args), "run", subject);
  }

  emaki::test::TempDir tmp_{
      "hostile_shot_" +
      std::string(::testing::UnitTest::GetInstance()->current_test_info()->name())};
  fs::path dir_ = tmp_.path();
};

// The base shot is valid up to its output: a bad case fails because of its one change.
TEST_F(HostileShot, BaseShotParses) {
  write("shot.toml", shot_text({}));
  EXPECT_NO_THROW(emaki::shot::open(p("shot.toml")));
}

// ---- bad keys, table-driven ----

struct BadKey {
  Slots slots;
  std::string key;
};

TEST_F(HostileShot, BadKeysNameTheirKeyPath) {
  const std::vector<BadKey> cases = {
      // 1. A printf width from the file: parsed by emaki and bounded, never given to printf.
      {{{"SCENE", "sequence = \"f_%2000000000d.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%99999999999999999999d.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%013d.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%s.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%-4d.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%*d.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%04d_%04d.exr\""}, {"SIZE", ""}}, "source.sequence"},
      {{{"SCENE", "sequence = \"f_%n.exr\""}, {"SIZE", ""}}, "source.sequence"},
      // 2/3. Frame numbers: int64 checked before narrowing, bounded, and a bounded count.
      {{{"FRAMES", "[0, 4294967297]"}}, "source.frames"},
      {{{"FRAMES", "[4294967296, 4294967297]"}}, "source.frames"},
      {{{"FRAMES", "[0, 1000000000]"}}, "source.frames"},
      {{{"FRAMES", "[0, 1e9]"}}, "source.frames"},
      {{{"FRAMES", "[0, 1000000]"}}, "source.frames"},  // 1,000,001 frames
      {{{"FRAMES", "[0, 10000001]"}}, "source.frames"},
      {{{"FRAMES", "[-1, 2]"}}, "source.frames"},
      {{{"FRAMES", "[-9223372036854775808, 9223372036854775807]"}}, "source.frames"},
      {{{"FRAMES", "[2147483647, 2147483647]"}}, "source.frames"},
      {{{"FRAMES", "[0, 2, 4]"}}, "source.frames"},
      // Sizes, weights, patch sizes: no float or int64 value is narrowed unchecked.
      {{{"SIZE", "size = [inf, 48]"}}, "source.size"},
      {{{"SIZE", "size = [nan, 48]"}}, "source.size"},
      {{{"SIZE", "size = [64.5, 48]"}}, "source.size"},
      {{{"SIZE", "size = [4294967360, 48]"}}, "source.size"},
      {{{"SIZE", "size = [100000, 100000]"}}, "source.size"},
      {{{"SOURCE", "fps = nan"}}, "source.fps"},
      {{{"SOURCE", "start = inf"}}, "source.start"},
      {{{"SOURCE", "start = 1e300"}}, "source.start"},
      {{{"LAYER", "pyramid_levels = 4294967297"}}, "layers.base.pyramid_levels"},
      {{{"SOURCE", "background = [0, 1e300, 0]"}}, "source.background"},
      {{{"LAYER", "patch_size = 4294967301"}}, "layers.base.patch_size"},
      {{{"LAYER", "patch_size = 5.0"}}, "layers.base.patch_size"},
      {{{"LAYER", "temporal_weight = nan"}}, "layers.base.temporal_weight"},
      {{{"LAYER", "uniformity = inf"}}, "layers.base.uniformity"},
      {{{"LAYER", "mask_dilate = inf"}}, "layers.base.mask_dilate"},
      {{{"LAYER", "guides = { normal = inf }"}}, "layers.base.guides.normal"},
      {{{"LAYER", "seed = -1"}}, "layers.base.seed"},
      {{{"LAYER", "order = 9223372036854775807"}}, "layers.base.order"},
      {{{"LAYER", "gradient = [[nan, 0, 0, 0]]"}}, "layers.base.gradient"},
      {{{"LAYER", "opacity = nan"}}, "layers.base.opacity"},
      {{{"COMPOSITING", "paper_scale = inf"}}, "compositing.paper_scale"},
      {{{"EXEMPLAR", "horizon = inf"}}, "exemplars.sphere.horizon"},
      {{{"EXEMPLAR", "elevation = nan"}}, "exemplars.sphere.elevation"},
      // 5. Camera, light and ground values: finite and in range, or refused.
      {{{"CAMERA", "azimuth = inf"}}, "source.camera.azimuth"},
      {{{"CAMERA", "azimuth = -inf"}}, "source.camera.azimuth"},
      {{{"CAMERA", "azimuth = nan"}}, "source.camera.azimuth"},
      {{{"CAMERA", "azimuth = 1e300"}}, "source.camera.azimuth"},
      {{{"CAMERA", "elevation = nan"}}, "source.camera.elevation"},
      {{{"CAMERA", "distance = inf"}}, "source.camera.distance"},
      {{{"CAMERA", "distance = 1e30"}}, "source.camera.distance"},
      {{{"CAMERA", "fov = nan"}}, "source.camera.fov"},
      {{{"CAMERA", "orbit = inf"}}, "source.camera.orbit"},
      {{{"CAMERA", "dolly = nan"}}, "source.camera.dolly"},
      {{{"CAMERA", "ortho_height = inf"}}, "source.camera.ortho_height"},
      {{{"CAMERA", "gltf_node = 4294967296"}}, "source.camera.gltf_node"},
      {{{"CAMERA", "position = [1e30, 0, 0]\ntarget = [0, 0, 0]\nmode = \"look_at\""}},
       "source.camera.position"},
      {{{"CAMERA", "target = [0, nan, 0]"}}, "source.camera.target"},
      {{{"CAMERA", "pan = [0, 0, inf]"}}, "source.camera.pan"},
      {{{"LIGHT", "softness = nan"}}, "source.light.softness"},
      {{{"GROUND", "height = -inf"}}, "source.ground.height"},
      {{{"GROUND", "size = 1e300"}}, "source.ground.size"},
      // 7. The pixel budget from the shot itself.
      {{{"TOP", "[limits]\nmax_pixels = 1000"}}, "source.size"},
      {{{"TOP", "[limits]\nmax_pixels = 0"}}, "limits.max_pixels"},
      {{{"TOP", "[limits]\nmax_pixels = nan"}}, "limits.max_pixels"},
      {{{"TOP", "[limits]\nmax_pixel = 1000"}}, "limits.max_pixel"},
  };
  for (const BadKey& c : cases) {
    SCOPED_TRACE(c.key);
    expect_bad_shot(shot_text(c.slots), c.key);
  }
}

// Errors the renderer and the reference sphere find name a neutral field; the shot file layer
// re-spells it as the key the user wrote (not a command-line option, not a guessed key).
TEST_F(HostileShot, RendererAndSphereErrorsNameTheirKey) {
  struct BadKey {
    Slots slots;
    std::string key;
  };
  const std::vector<BadKey> cases = {
      {{{"SCENE", "scene = \"@DATA@/scenes/Fox.glb\"\nclip = \"Nope\""}}, "source.clip"},
      {{{"SOURCE", "start = 1000"}}, "source.start"},
      {{{"FRAMES", "[0, 500]"}}, "source.frames"},
      {{{"CAMERA", "mode = \"gltf\"\ngltf_node = 0"}}, "source.camera.gltf_node"},
      {{{"EXEMPLAR", "horizon = -100000"}}, "exemplars.sphere.horizon"},
  };
  for (const BadKey& c : cases) {
    SCOPED_TRACE(c.key);
    expect_bad_shot(shot_text(c.slots), c.key);
  }
}

// ---- 7. limits.max_pixels and --max-pixels ----

TEST_F(HostileShot, CommandLineMaxPixelsOverridesTheShots) {
  // With the shot's budget of 1000 pixels source.size fails; the command line's larger budget
  // wins, so parsing gets on to the next (deliberate) error.
  const std::string text =
      shot_text({{"TOP", "[limits]\nmax_pixels = 1000"}, {"LAYER", "patch_size = 4"}});
  expect_bad_shot(text, "source.size");
  expect_bad_shot(text, "layers.base.patch_size", {"--max-pixels", "1000000"});
  // And the other way round: a small budget on the command line beats a large one in the file.
  expect_bad_shot(shot_text({{"TOP", "[limits]\nmax_pixels = 1000000000"}}), "source.size",
                  {"--max-pixels", "100"});
}

// One shot's budget governs that shot only: `emaki plan a.toml b.toml` plans b under the default.
TEST_F(HostileShot, OneShotsMaxPixelsDoesNotGovernTheNext) {
  // 1.2 M pixels: a's 64x48 frames and 1200x912 painting fit; b's 1200x1100 frames do not.
  write("a.toml", shot_text({{"TOP", "[limits]\nmax_pixels = 1200000"}}));
  write("b.toml", std::regex_replace(shot_text({{"SIZE", "size = [1200, 1100]"}}),
                                     std::regex("folder = \"out\""), "folder = \"out_b\""));
  const CliResult r = emaki({"plan", "a.toml", "b.toml"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.signal, 0);
}

// ---- 10. memory: the estimated peak is checked before any work ----

TEST_F(HostileShot, AShotTooLargeForTheMachineIsRefusedAtOnce) {
  // 16384x16384 is within the pixel budget; its layer task needs ~100 GB.
  expect_bad_shot(shot_text({{"SIZE", "size = [16384, 16384]"}}), "shot.toml");
  write("shot.toml", shot_text({{"SIZE", "size = [16384, 16384]"}}));
  const CliResult r = emaki({"run", "shot.toml"});
  EXPECT_NE(r.err.find("16384x16384 frames needs about"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("GB of memory"), std::string::npos) << r.err;
}

TEST_F(HostileShot, MaxMemoryIsALimitOfItsOwn) {
  expect_bad_shot(shot_text({}), "--max-memory", {"--max-memory", "64"});
  for (const char* bad : {"0", "-5", "8X", "G", "+8", "99999999999999999999"})
    expect_bad_shot(shot_text({}), "--max-memory", {"--max-memory", bad});
  for (const char* task : {"prepare", "composite"}) {
    write("shot.toml", shot_text({}));
    expect_refused(emaki({"task", task, "shot.toml", "--max-memory", "1"}), "task", "--max-memory");
  }
}

// ---- 4. size and depth before toml++ parses ----

TEST_F(HostileShot, HugeAndDeepFilesAreRefusedBeforeParsing) {
  const int n = 200000;  // ~400 KB each
  std::string dotted = "a";
  for (int i = 0; i < n; ++i) dotted += ".a";
  std::string header = "[" + dotted + "]\nx = 1\n";
  std::string inline_tables = "x = ";
  for (int i = 0; i < n / 2; ++i) inline_tables += "{a=";
  inline_tables += "1" + std::string(n / 2, '}') + "\n";
  const std::string arrays = "x = " + std::string(n, '[') + std::string(n, ']') + "\n";
  const std::string mixed = [&] {
    std::string s = "x = ";
    for (int i = 0; i < n / 2; ++i) s += "[{a=";
    return s + "1" + std::string(n / 2, '}') + "\n";  // unbalanced on purpose
  }();
  for (const std::string& text : {dotted + " = 1\n", header, inline_tables, arrays, mixed}) {
    SCOPED_TRACE(text.substr(0, 40));
    expect_bad_shot(text, "shot.toml");
  }
  // 65 levels refused, 64 fine (then the shot is incomplete: 'source' is required).
  std::string a65 = "a", a64 = "a";
  for (int i = 0; i < 64; ++i) a65 += ".a";
  for (int i = 0; i < 63; ++i) a64 += ".a";
  expect_bad_shot(a65 + " = 1\n", "shot.toml");
  expect_bad_shot(a64 + " = 1\n", "a");  // an unknown top-level key, parsed fine

  // Over 1 MB: refused from its size, before toml++ sees it.
  std::string big = shot_text({});
  big += "# " + std::string((1 << 20) + 16, 'x') + "\n";
  expect_bad_shot(big, "shot.toml");
  // Not a regular file: /dev/zero is read no further than the cap.
  expect_refused(emaki({"run", "/dev/zero"}), "run", "/dev/zero");
}

// Brackets, braces and dots inside strings and comments are not nesting.
TEST_F(HostileShot, DepthScanSkipsStringsAndComments) {
  const std::string deep = std::string(300, '[') + std::string(300, '{') + std::string(300, '.');
  const std::string text = "# " + deep + "\n" +
                           shot_text({{"SOURCE", "premultiplied = false"},
                                      {"TOP", "# \"" + deep + "\n"},
                                      {"LAYER", "channel = 'luminance' # " + deep}}) +
                           "\n# '''" + deep + "\n";
  // Parses up to the deliberate error: premultiplied applies to sequences only.
  write("shot.toml", text);
  expect_bad_shot(text, "source.premultiplied");
  const std::string strings =
      shot_text({{"SCENE", "scene = \"@DATA@/scenes/Fox.glb\"\nclip = \"\"\"" + deep + "\n" + deep +
                               "\"\"\""}});
  expect_bad_shot(std::regex_replace(strings, std::regex("@DATA@"), kData), "source.clip");
  const std::string literal =
      shot_text({{"SCENE", "scene = \"@DATA@/scenes/Fox.glb\"\nclip = '" + deep + "'"}});
  expect_bad_shot(std::regex_replace(literal, std::regex("@DATA@"), kData), "source.clip");
}

// ---- 6. echoed values are capped ----

TEST_F(HostileShot, LongValuesAreEchoedCapped) {
  const std::string huge(300000, 'x');
  // A 300 KB clip name: load succeeds, the renderer refuses the clip, the line stays short.
  expect_bad_shot(
      shot_text({{"SCENE", "scene = \"@DATA@/scenes/Fox.glb\"\nclip = \"" + huge + "\""}}),
      "source.clip");
  expect_bad_shot(shot_text({{"LAYER", "blend = \"" + huge + "\""}}), "layers.base.blend");
  expect_bad_shot(shot_text({{"LAYER", "[layers.other]\nexemplar = \"" + huge + "\""}}),
                  "layers.other.exemplar");
  expect_bad_shot(shot_text({{"SCENE", "sequence = \"" + huge + "%s\""}, {"SIZE", ""}}),
                  "source.sequence");
  // An unknown key of 300 KB: the key path itself is capped.
  write("shot.toml", shot_text({{"LAYER", huge + " = 1"}}));
  const CliResult r = emaki({"run", "shot.toml"});
  expect_refused(r, "run", "layers.base." + huge.substr(0, 80) + "... (300000 bytes)");
  // On the command line too (one argument may be 128 KB on Linux).
  const std::string clip(100000, 'c');
  expect_refused(emaki({"render", kData + "/scenes/Fox.glb", "--out", "out", "--clip", clip}),
                 "render", "--clip");
}

// ---- 2/5. `emaki render` / `emaki template` / `emaki run` options ----

TEST_F(HostileShot, BadRenderOptionsNameTheOption) {
  struct Opt {
    std::vector<std::string> args;
    std::string option;
  };
  const std::vector<Opt> cases = {
      {{"--frames", "2147483647", "--loop"}, "--frames"},
      {{"--frames", "0-2147483647", "--loop"}, "--frames"},
      {{"--frames", "0-2147483648"}, "--frames"},
      {{"--frames", "0-99999999999999999999"}, "--frames"},
      {{"--frames", "0-1000000", "--loop"}, "--frames"},  // 1,000,001 frames
      {{"--frames", "10000001", "--loop"}, "--frames"},
      {{"--frames", "5-4"}, "--frames"},
      {{"--azimuth", "inf"}, "--azimuth"},
      {{"--azimuth", "nan"}, "--azimuth"},
      {{"--azimuth", "1e30"}, "--azimuth"},
      {{"--elevation", "nan"}, "--elevation"},
      {{"--distance", "inf"}, "--distance"},
      {{"--fov", "nan"}, "--fov"},
      {{"--ortho", "inf"}, "--ortho"},
      {{"--orbit", "-inf"}, "--orbit"},
      {{"--dolly", "nan"}, "--dolly"},
      {{"--softness", "nan"}, "--softness"},
      {{"--outline-width", "nan"}, "--outline-width"},
      {{"--crease", "nan"}, "--crease"},
      {{"--ground-size", "inf"}, "--ground-size"},
      {{"--ground-height", "nan"}, "--ground-height"},
      {{"--fps", "nan"}, "--fps"},
      {{"--fps", "inf"}, "--fps"},
      {{"--fps", "1e-30"}, "--fps"},
      {{"--start", "nan"}, "--start"},
      {{"--start", "inf"}, "--start"},
      {{"--camera", "1e30,0,0", "--target", "0,0,0"}, "--camera"},
      {{"--target", "0,nan,0"}, "--target"},
      {{"--pan", "inf,0,0"}, "--pan"},
      {{"--light", "nan,1,1"}, "--light"},
      {{"--size", "100000x100000"}, "--size"},
      {{"--size", "4096x4096", "--max-pixels", "1000"}, "--size"},
  };
  for (const Opt& c : cases) {
    SCOPED_TRACE(c.args[0] + " " + c.args[1]);
    std::vector<std::string> args = {"render", kData + "/scenes/Fox.glb", "--out", "out"};
    if (c.args[0] != "--size") args.insert(args.end(), {"--size", "32x24"});
    args.insert(args.end(), c.args.begin(), c.args.end());
    expect_refused(emaki(args), "render", c.option);
  }
}

TEST_F(HostileShot, BadTemplateOptionsNameTheOption) {
  for (const auto& [option, value] :
       std::vector<std::pair<std::string, std::string>>{{"--elevation", "nan"},
                                                        {"--fov", "nan"},
                                                        {"--softness", "nan"},
                                                        {"--outline-width", "nan"},
                                                        {"--horizon", "inf"},
                                                        {"--horizon", "-1e30"},
                                                        {"--sphere", "nan,1,1"},
                                                        {"--light", "inf,1,1"}}) {
    SCOPED_TRACE(option + " " + value);
    expect_refused(emaki({"template", "--out", "out", "--size", "32x24", option, value}),
                   "template", option);
  }
}

TEST_F(HostileShot, BadRunFramesNameTheOption) {
  write("shot.toml", shot_text({}));
  for (const char* f : {"0-4294967297", "99999999999", "10000001", "0-x"}) {
    SCOPED_TRACE(f);
    expect_refused(emaki({"run", "shot.toml", "--frames", f}), "run", "--frames");
  }
}

// ---- every reproducer committed for the fuzz target fails cleanly too ----

TEST_F(HostileShot, CommittedReproducers) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(kHostile + "/shot")) {
    SCOPED_TRACE(e.path().string());
    fs::copy_file(e.path(), dir_ / "shot.toml", fs::copy_options::overwrite_existing);
    const CliResult r = emaki({"run", "shot.toml"});
    EXPECT_FALSE(r.timed_out);
    EXPECT_EQ(r.signal, 0);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_LT(r.err.size(), 600u);
    EXPECT_FALSE(fs::exists(dir_ / "out"));
    ++n;
  }
  EXPECT_GT(n, 0);
}

// ---- 8. an image sequence's frames must all have the first frame's size ----

TEST_F(HostileShot, SequenceFrameOfAnotherSizeIsAnError) {
  const std::vector<std::string> names = emaki::render::channel_names();
  auto frame = [&](int w, int h, const std::string& file) {
    emaki::Image<float> img(w, h, int(names.size()));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) img(x, y, emaki::render::kAlpha) = 1.0f;
    emaki::io::WriteOptions wo;
    wo.format = emaki::io::SampleFormat::kHalf;
    wo.channel_names = names;
    emaki::io::write_image(p(file), img.cview(), wo);
  };
  frame(8, 6, "f_0000.exr");
  frame(4, 3, "f_0001.exr");
  frame(8, 6, "passes.exr");
  write("shot.toml",
        std::regex_replace(
            shot_text({{"SCENE", "sequence = \"f_%04d.exr\""}, {"FRAMES", "[0, 1]"}, {"SIZE", ""}}),
            std::regex("aa = 1\n|\\[source.camera\\]\n|\\[source.light\\]\n"
                       "direction = \\[0.3, 0.9, -0.3\\]\n|\\[source.ground\\]\n"),
            ""));
  const emaki::pipeline::Shot shot = emaki::shot::open(p("shot.toml"));
  EXPECT_EQ(shot.source.width, 8);
  const auto frames = emaki::shot::open_frames(shot);
  EXPECT_NO_THROW(frames->passes(0));
  try {
    frames->passes(1);
    ADD_FAILURE() << "a 4x3 frame in an 8x6 sequence was accepted";
  } catch (const emaki::Error& e) {
    EXPECT_EQ(e.subject(), p("f_0001.exr"));
  }
}

// frame_file bounds the width itself, for any caller.
TEST(FrameFile, WidthIsBounded) {
  EXPECT_EQ(emaki::io::frame_file("f_%04d.exr", 7), "f_0007.exr");
  EXPECT_EQ(emaki::io::frame_file("f_%012d.exr", 7), "f_000000000007.exr");
  EXPECT_THROW(emaki::io::frame_file("f_%013d.exr", 7), emaki::Error);
  EXPECT_THROW(emaki::io::frame_file("f_%2000000000d.exr", 7), emaki::Error);
  EXPECT_THROW(emaki::io::frame_file("f_%99999999999999999999d.exr", 7), emaki::Error);
}

}  // namespace
