// Colour management end to end (`emaki render` / `emaki run` on tiny shots), against
// OpenColorIO's own ocioconvert: unknown names refused before any frame runs, the defaults
// being today's bytes, an ACEScg studio render giving the Rec.709 render's layers, and the
// preview PNG through a view being ocioconvert's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include "core/image.h"
#include "io/image_io.h"
#include "tests/cli_run.h"
#include "tests/small_painting.h"

namespace fs = std::filesystem;
using namespace emaki;

namespace {

const std::string kData = EMAKI_TEST_DATA;
const std::string kOcioconvert = "/usr/bin/ocioconvert";

// Fox walking at 64x48, two frames, one base layer (coloured by the albedo pass) over a paper.
const char* kShot = R"(threads = 2
@COLOUR@
[source]
@SOURCE@
frames = [0, 1]

[exemplars.sphere]
painting = "painting.png"
sphere = [50.7, 41.2, 20.2]
elevation = 20
light = [0.3, 0.9, -0.3]
aa = 1
@EXEMPLAR@

[layers.base]
kind = "base"
exemplar = "sphere"

[compositing]
paper = "@DATA@/papers/roughpaper.png"
@COMPOSITING@

[outputs]
folder = "@OUT@"
mp4 = false
contact_sheet = false
composite_exr = true
@OUTPUTS@
)";

const std::string kSceneSource =
    "scene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\nsize = [64, 48]\naa = 1";

struct Parts {
  std::string colour = {}, source = kSceneSource, exemplar = {}, compositing = {}, outputs = {},
              out = "out";
};

class ColourCli : public ::testing::Test {
 protected:
  void SetUp() override {
    ::unsetenv("OCIO");  // the built-in config, whatever the machine sets
    dir_ = fs::temp_directory_path() /
           ("emaki_colour_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    test::write_small_painting(kData + "/stylit/source_style.png", p("painting.png"));
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string p(const std::string& name) const { return (dir_ / name).string(); }

  test::CliResult run(const std::vector<std::string>& args, const std::string& binary = "") {
    test::CliOptions o;
    o.cwd = dir_;
    // ocioconvert reads its config from $OCIO: emaki's built-in one, from the source tree.
    if (binary == kOcioconvert)
      o.env = {"OCIO=" + std::string(EMAKI_SOURCE_DIR) + "/src/colour/emaki.ocio"};
    return test::run_cli(binary.empty() ? EMAKI_BINARY : binary, args, o);
  }
  // Writes the shot made of `parts` to `name` and runs it.
  test::CliResult run_shot(const Parts& parts, const std::string& name = "shot.toml") {
    std::string s = kShot;
    for (const auto& [tag, value] :
         {std::pair{"@COLOUR@", parts.colour}, std::pair{"@SOURCE@", parts.source},
          std::pair{"@EXEMPLAR@", parts.exemplar}, std::pair{"@COMPOSITING@", parts.compositing},
          std::pair{"@OUTPUTS@", parts.outputs}, std::pair{"@OUT@", parts.out},
          std::pair{"@DATA@", kData}})
      s = std::regex_replace(s, std::regex(tag), value);
    std::ofstream(p(name)) << s;
    return run({"run", name});
  }
  // `emaki run` fails with one line naming `key` and `name`, and writes nothing.
  void expect_refused(const Parts& parts, const std::string& key, const std::string& name) {
    fs::remove_all(dir_ / "out");
    const test::CliResult r = run_shot(parts);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_EQ(test::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(key + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out")) << r.err;
  }

  fs::path dir_;
};

// The largest difference between two images' first three channels.
float max_difference(const Image<float>& a, const Image<float>& b) {
  EXPECT_EQ(a.width(), b.width());
  EXPECT_EQ(a.height(), b.height());
  float d = 0.0f;
  for (int y = 0; y < std::min(a.height(), b.height()); ++y)
    for (int x = 0; x < std::min(a.width(), b.width()); ++x)
      for (int c = 0; c < std::min({3, a.channels(), b.channels()}); ++c)
        d = std::max(d, std::abs(a(x, y, c) - b(x, y, c)));
  return d;
}

bool same_bytes(const fs::path& a, const fs::path& b) {
  return test::slurp_file(a) == test::slurp_file(b);
}

constexpr float kOneLevel8 = 1.0f / 255.0f;

TEST_F(ColourCli, UnknownNamesAreRefusedBeforeAnyFrame) {
  expect_refused({.exemplar = "colorspace = \"sRGB textur\""}, "exemplars.sphere.colorspace",
                 "'sRGB textur' in the built-in config; nearest: 'sRGB texture'");
  expect_refused({.compositing = "paper_colorspace = \"ACEScc\""}, "compositing.paper_colorspace",
                 "nearest: 'ACEScg'");
  expect_refused({.outputs = "view = \"filmic\""}, "outputs.view", "nearest: 'Filmic'");
  expect_refused({.outputs = "display = \"P3\""}, "outputs.display", "unknown display 'P3'");
  expect_refused({.compositing = "space = \"linear\""}, "compositing.space", "scene_linear");
  expect_refused({.source = kSceneSource + "\npasses_colorspace = \"ACEScg\""},
                 "source.passes_colorspace", "'sequence' source only");
  std::ofstream(p("broken.ocio")) << "ocio_profile_version: 2\nroles: {scene_linear: nowhere}\n";
  expect_refused({.colour = "[colour]\nconfig = \"broken.ocio\""}, "colour.config", "broken.ocio");
}

// The defaults are the built-in config's sRGB texture / Standard: naming them changes no byte.
TEST_F(ColourCli, DefaultsAreTodaysBytes) {
  ASSERT_EQ(run_shot({}).exit_code, 0);
  const test::CliResult r =
      run_shot({.exemplar = "colorspace = \"sRGB texture\"",
                .compositing = "paper_colorspace = \"sRGB texture\"\nspace = \"display\"",
                .outputs = "display = \"sRGB\"\nview = \"Standard\"",
                .out = "named"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"composite/frame_0001.png", "layers/base/base_0001.png"})
    EXPECT_TRUE(same_bytes(dir_ / "out" / f, dir_ / "named" / f)) << f;
}

// Fox passes rendered by emaki (scene-linear Rec.709), their albedo converted to ACEScg by
// ocioconvert: with source.passes_colorspace = "ACEScg" the shot gives the same layers and a
// composite within 1 level of the Rec.709 passes'.
TEST_F(ColourCli, AcescgStudioPassesGiveTheRec709Layers) {
  if (!fs::exists(kOcioconvert)) GTEST_SKIP() << "ocioconvert not installed (scripts/setup.sh)";
  ASSERT_EQ(run({"render", kData + "/scenes/Fox.glb", "--clip", "Walk", "--frames", "0-1", "--size",
                 "64x48", "--aa", "1", "--out", "rec709"})
                .exit_code,
            0);
  fs::create_directories(dir_ / "acescg");
  std::string pattern;
  for (const auto& e : fs::directory_iterator(dir_ / "rec709")) {
    if (e.path().extension() != ".exr") continue;
    const std::string name = e.path().filename().string();
    pattern = std::regex_replace(name, std::regex("[0-9]{4}"), "%04d");
    const io::AnyImage frame = io::read_image(e.path().string());
    // The file's channels are in its own (alphabetical) order.
    int rgb[3];
    for (int c = 0; c < 3; ++c) {
      const std::string channel = std::string("albedo.") + "RGB"[c];
      const auto& names = frame.channel_names;
      rgb[c] = int(std::find(names.begin(), names.end(), channel) - names.begin());
      ASSERT_LT(rgb[c], int(names.size())) << channel;
    }
    const Image<float> passes = frame.to_float();
    Image<float> albedo(passes.width(), passes.height(), 3);
    for (int y = 0; y < passes.height(); ++y)
      for (int x = 0; x < passes.width(); ++x)
        for (int c = 0; c < 3; ++c) albedo(x, y, c) = passes(x, y, rgb[c]);
    io::WriteOptions f;
    f.format = io::SampleFormat::kFloat;
    io::write_image(p("albedo.exr"), albedo.cview(), f);
    const test::CliResult c =
        run({"albedo.exr", "scene-linear Rec.709", "albedo_acescg.exr", "ACEScg"}, kOcioconvert);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const Image<float> acescg = io::read_image_float(p("albedo_acescg.exr"));
    ASSERT_GT(max_difference(acescg, albedo), 0.01f);  // the conversion did something
    Image<float> out = frame.to_float();
    for (int y = 0; y < out.height(); ++y)
      for (int x = 0; x < out.width(); ++x)
        for (int c = 0; c < 3; ++c) out(x, y, rgb[c]) = acescg(x, y, c);
    f.channel_names = frame.channel_names;
    io::write_image((dir_ / "acescg" / name).string(), out.cview(), f);
  }
  ASSERT_FALSE(pattern.empty());
  test::CliResult r = run_shot({.source = "sequence = \"rec709/" + pattern + "\"", .out = "a"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_shot({.source = "sequence = \"acescg/" + pattern + "\"\npasses_colorspace = \"ACEScg\"",
                .out = "b"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int f : {0, 1}) {
    const std::string n = "000" + std::to_string(f);
    EXPECT_LE(max_difference(io::read_image_float(p("a/layers/base/base_" + n + ".exr")),
                             io::read_image_float(p("b/layers/base/base_" + n + ".exr"))),
              kOneLevel8);
    EXPECT_LE(max_difference(io::read_image_float(p("a/composite/frame_" + n + ".png")),
                             io::read_image_float(p("b/composite/frame_" + n + ".png"))),
              kOneLevel8)
        << n;
  }
}

// compositing.space = "scene_linear" and the Filmic view: the composite EXR is scene-linear and
// says so; the PNG is ocioconvert's rendering of it through sRGB / Filmic, within 1 level.
TEST_F(ColourCli, SceneLinearCompositeThroughTheFilmicView) {
  if (!fs::exists(kOcioconvert)) GTEST_SKIP() << "ocioconvert not installed (scripts/setup.sh)";
  const test::CliResult r =
      run_shot({.compositing = "space = \"scene_linear\"", .outputs = "view = \"Filmic\""});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const test::CliResult c = run({"--view", "out/composite/frame_0001.exr", "scene-linear Rec.709",
                                 "filmic.exr", "sRGB", "Filmic"},
                                kOcioconvert);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  // From the half EXR: 3.1e-4 apart when measured (0.08 of an 8-bit level).
  EXPECT_LE(max_difference(io::read_image_float(p("filmic.exr")),
                           io::read_image_float(p("out/composite/frame_0001.png"))),
            kOneLevel8);
  const std::string header = test::slurp_file(dir_ / "out/composite/frame_0001.exr");
  EXPECT_NE(header.find("colorSpace"), std::string::npos);
  EXPECT_NE(header.find("scene-linear Rec.709"), std::string::npos);
  EXPECT_NE(header.find("chromaticities"), std::string::npos);
}

}  // namespace
