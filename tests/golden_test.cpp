// Golden images: runs the emaki binary on small inputs and compares what it writes with the
// expected files in tests/golden/ (its README lists the inputs, commands and tolerances).
// EMAKI_UPDATE_GOLDEN=1 in the environment rewrites the expected files from this build instead.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "tests/cli_run.h"

namespace {

namespace fs = std::filesystem;
using emaki::Image;
using emaki::test::CliResult;
using emaki::test::TempDir;

const std::string kGolden = EMAKI_GOLDEN;
const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";

// The engine and the renderer are deterministic (integer patch distances, counter-based random
// numbers, fixed reduction orders; results do not depend on the thread count), so their
// outputs must match to the last bit.
constexpr float kExact = 0.0f;

bool updating() {
  const char* v = std::getenv("EMAKI_UPDATE_GOLDEN");
  return v && std::string(v) == "1";
}

// Runs `emaki args...`; the test fails (and says why) unless it succeeds.
::testing::AssertionResult run_emaki(const std::vector<std::string>& args) {
  const CliResult r = emaki::test::run_cli(EMAKI_BINARY, args);
  if (r.exit_code == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "emaki exited with " << r.exit_code << ": " << r.err;
}

// Where `actual` and the golden file `name` differ by more than `tolerance`; empty when they
// match (same size and channels). `channels` picks the golden file's channels by name, in that
// order (EXR files store them sorted).
std::string difference(const Image<float>& actual, const std::string& name, float tolerance,
                       const std::vector<std::string>& channels = {}) {
  const std::string path = kGolden + "/" + name;
  if (!fs::exists(path)) return path + " is missing (EMAKI_UPDATE_GOLDEN=1 writes it)";
  emaki::io::ReadOptions ro;
  ro.channels = channels;
  const Image<float> expected = emaki::io::read_image_float(path, ro);
  if (actual.width() != expected.width() || actual.height() != expected.height() ||
      actual.channels() != expected.channels())
    return fmt::format("{}: {}x{}x{} but expected {}x{}x{}", name, actual.width(), actual.height(),
                       actual.channels(), expected.width(), expected.height(), expected.channels());
  float worst = 0.0f;
  int worst_x = 0, worst_y = 0, worst_c = 0;
  int64_t differing = 0;
  for (int y = 0; y < actual.height(); ++y)
    for (int x = 0; x < actual.width(); ++x)
      for (int c = 0; c < actual.channels(); ++c) {
        const float d = std::abs(actual(x, y, c) - expected(x, y, c));
        differing += d > tolerance || std::isnan(d);
        if (d > worst || (std::isnan(d) && !std::isnan(worst)))
          worst = d, worst_x = x, worst_y = y, worst_c = c;
      }
  if (differing == 0) return "";
  return fmt::format(
      "{}: {} samples differ by more than {}, the most at ({}, {}) channel {}: {} "
      "vs expected {}",
      name, differing, tolerance, worst_x, worst_y, worst_c, actual(worst_x, worst_y, worst_c),
      expected(worst_x, worst_y, worst_c));
}

// Compares `actual` with the golden file `name`; when updating, rewrites the golden file with
// `write` instead, if they differ (a file that still matches is left as it is).
template <typename Write>
void check(const Image<float>& actual, const std::string& name, float tolerance,
           const std::vector<std::string>& channels, Write write) {
  const std::string diff = difference(actual, name, tolerance, channels);
  if (updating()) {
    if (!diff.empty()) write(kGolden + "/" + name);
    return;
  }
  EXPECT_EQ(diff, "");
}

// An output file against the golden file `name`, which is a copy of it.
void check_file(const std::string& output, const std::string& name, float tolerance) {
  check(emaki::io::read_image_float(output), name, tolerance, {}, [&](const std::string& golden) {
    fs::copy_file(output, golden, fs::copy_options::overwrite_existing);
  });
}

// Some channels of a multilayer EXR against the golden file `name`, which holds only those.
void check_channels(const std::string& output, const std::vector<std::string>& channels,
                    const std::string& name, float tolerance) {
  emaki::io::ReadOptions ro;
  ro.channels = channels;
  const Image<float> actual = emaki::io::read_image_float(output, ro);
  check(actual, name, tolerance, channels, [&](const std::string& golden) {
    emaki::io::WriteOptions wo;
    wo.format = emaki::io::SampleFormat::kHalf;  // as emaki render writes them
    wo.channel_names = channels;
    emaki::io::write_image(golden, actual.cview(), wo);
  });
}

TEST(Golden, SynthStylit) {
  const TempDir dir("golden_synth");
  const std::string in = kGolden + "/stylit_64x48/";
  std::vector<std::string> args{"synth", "-style", in + "source_style.png"};
  for (const char* g : {"fullgi", "dirdif", "dirspc", "indirb"})
    args.insert(args.end(), {"-guide", in + "source_" + g + ".png", in + "target_" + g + ".png",
                             "-weight", "0.5"});
  args.insert(args.end(), {"-output", dir / "out.png", "--quiet"});
  ASSERT_TRUE(run_emaki(args));
  check_file(dir / "out.png", "synth_stylit_64x48.png", kExact);
}

TEST(Golden, RenderFox) {
  const TempDir dir("golden_render");
  ASSERT_TRUE(run_emaki({"render", kScenes + "Fox.glb", "--size", "64x48", "--frames", "5", "--out",
                         dir / "out", "--quiet"}));
  check_channels(dir / "out/frame_0005.exr",
                 {"normal.X", "normal.Y", "normal.Z", "diffuse.Y", "outline.Y"},
                 "render_fox_64x48_f5.exr", kExact);
}

TEST(Golden, Template) {
  const TempDir dir("golden_template");
  ASSERT_TRUE(run_emaki({"template", "--size", "64x48", "--out", dir / "out"}));
  check_file(dir / "out/template.png", "template_64x48.png", kExact);
  check_channels(dir / "out/reference.exr", {"normal.X", "normal.Y", "normal.Z", "shadow.Y"},
                 "template_reference_64x48.exr", kExact);
}

}  // namespace
