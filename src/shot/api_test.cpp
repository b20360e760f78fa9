// The shot API as every front end calls it: run, composite and flicker on a tiny shot, and the
// neutral field names of a Request's errors.
#include "shot/api.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"
#include "io/image_io.h"
#include "tests/error_of.h"
#include "tests/file_bytes.h"
#include "tests/small_painting.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

class ShotApi : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ =
        fs::temp_directory_path() /
        ("emaki_shot_api_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    inputs_ = folder_.string() + "_in";
    fs::remove_all(inputs_);
    fs::create_directories(inputs_);
    test::write_small_painting(kData + "/stylit/source_style.png", pastel());
  }
  void TearDown() override {
    fs::remove_all(folder_);
    fs::remove_all(inputs_);
  }
  std::string pastel() const { return (inputs_ / "pastel.png").string(); }

  pipeline::Shot tiny() const {
    const std::string text =
        "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\n" +
        "frames = [0, 2]\nsize = [40, 24]\naa = 1\n[exemplars.sphere]\npainting = \"" + pastel() +
        "\"\n[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n" +
        "[layers.ink]\nkind = \"outline\"\nexemplar = \"sphere\"\ntemporal = false\n" +
        "[outputs]\nfolder = \"" + folder_.string() + "\"\nmp4 = false\n";
    return open_text(text, (folder_.parent_path() / "tiny.toml").string());
  }

  fs::path folder_, inputs_;
};

TEST_F(ShotApi, RunResumesAndComposites) {
  const pipeline::Shot shot = tiny();
  Request r;
  int progress_calls = 0;
  r.progress = [&](const pipeline::Progress&) { ++progress_calls; };
  const RunResult first = run(shot, r);
  EXPECT_EQ(first.report.synthesized, 6);
  EXPECT_EQ(first.report.composited, 3);
  EXPECT_GT(progress_calls, 0);
  ASSERT_EQ(first.previews.size(), 1u);  // the contact sheet (mp4 = false)
  EXPECT_TRUE(fs::exists(first.previews[0]));
  const RunResult again = run(shot, Request{});
  EXPECT_EQ(again.report.synthesized, 0);
  EXPECT_EQ(again.report.reused, 6);
  Request two;
  two.first_frame = 1, two.last_frame = 2, two.previews = false;
  EXPECT_EQ(composite(shot, two).composited, 2);
  const FlickerResult f = flicker(shot, "base", Request{});
  ASSERT_EQ(f.frames.size(), 2u);
  EXPECT_EQ(f.frames[0].frame, 1);
  EXPECT_GT(f.mean.all.mean(), 0.0);
}

// Two styles mixed: the hatching layer's blend is a compositing setting, so changing only it
// re-colours the finished layers (no synthesis, layer files untouched) and changes the mix.
TEST_F(ShotApi, HatchingBlendChangesTheMixWithoutSynthesis) {
  // The town's 800x600 hatching at a quarter of its size, its sphere with it.
  const std::string hatching = (inputs_ / "hatching.png").string();
  test::write_small_painting(std::string(EMAKI_SOURCE_DIR) + "/examples/town/hatching.png",
                             hatching, 200, 150);
  auto text = [&](const std::string& blend) {
    return "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\n" +
           "frames = [0, 1]\nsize = [48, 32]\naa = 1\n[exemplars.pastel]\npainting = \"" +
           pastel() + "\"\n[exemplars.hatching]\npainting = \"" + hatching +
           "\"\nsphere = [100, 75, 45]\n[layers.base]\n" +
           "kind = \"base\"\nexemplar = \"pastel\"\n[layers.hatching]\nexemplar = \"hatching\"\n" +
           "guides = { normal = 1, diffuse = 1 }\nmask = \"covered\"\nalpha = \"inverse_value\"\n" +
           "gradient = [[0, 0.2, 0.15, 0.3], [1, 1, 1, 1]]\nopacity = 0.8\nblend = \"" + blend +
           "\"\n[outputs]\nfolder = \"" + folder_.string() + "\"\nmp4 = false\n";
  };
  const std::string path = (folder_.parent_path() / "mix.toml").string();
  const pipeline::Shot multiply = open_text(text("multiply"), path);
  Request r;
  r.previews = false;
  EXPECT_EQ(run(multiply, r).report.synthesized, 4);
  const fs::path frame = folder_ / "composite" / "frame_0001.png";
  const fs::path layer = folder_ / "layers" / "hatching" / "hatching_0001.exr";
  const Image<float> before = io::read_image_float(frame.string());
  const Image<float> layer_before = io::read_image_float(layer.string());
  const auto layer_time = fs::last_write_time(layer);

  const pipeline::Shot screen = open_text(text("screen"), path);
  EXPECT_EQ(composite(screen, r).composited, 2);
  const Image<float> after = io::read_image_float(frame.string());
  int changed = 0;  // pixels that moved by more than one 8-bit step
  for (int y = 0; y < after.height(); ++y)
    for (int x = 0; x < after.width(); ++x)
      for (int c = 0; c < 3; ++c)
        changed += std::abs(after(x, y, c) - before(x, y, c)) > 1 / 255.0f;
  EXPECT_GT(changed, 20);
  EXPECT_EQ(fs::last_write_time(layer), layer_time);
  const Image<float> layer_after = io::read_image_float(layer.string());
  for (int y = 0; y < layer_after.height(); ++y)
    for (int x = 0; x < layer_after.width(); ++x)
      ASSERT_EQ(layer_after(x, y, 0), layer_before(x, y, 0));
  // A run with the new blend finds every layer frame finished: the blend is not synthesis.
  const RunResult again = run(screen, r);
  EXPECT_EQ(again.report.synthesized, 0);
  EXPECT_EQ(again.report.reused, 4);
}

using test::error_of;

// A Request's errors name neutral fields that each front end spells its own way.
TEST_F(ShotApi, RequestErrorsNameNeutralFields) {
  const pipeline::Shot shot = tiny();
  Request unknown;
  unknown.layers = {"nope"};
  EXPECT_EQ(error_of([&] { run(shot, unknown); }).field(), "layers");
  Request outside;
  outside.first_frame = 0, outside.last_frame = 9;
  EXPECT_EQ(error_of([&] { run(shot, outside); }).field(), "frames");
  EXPECT_FALSE(fs::exists(folder_));  // refused before anything was written
  EXPECT_EQ(error_of([&] { flicker(shot, "nope", Request{}); }).field(), "layer");
  Request one;
  one.first_frame = one.last_frame = 1;
  EXPECT_EQ(error_of([&] { flicker(shot, "base", one); }).field(), "frames");
  // Nothing was synthesized: flicker names the layer by its shot key.
  EXPECT_EQ(error_of([&] { flicker(shot, "base", Request{}); }).subject(), "layers.base");
}

// The QA maps (store/qa_maps.h): one PNG per measured frame under qa/KIND/LAYER/, the same bytes
// every time, not all black; a measure refused writes none.
TEST_F(ShotApi, QaMapsAreWrittenPerFrameTheSameEachTime) {
  const pipeline::Shot shot = tiny();
  Request maps;
  maps.qa_maps = true;
  EXPECT_EQ(error_of([&] { flicker(shot, "base", maps); }).subject(), "layers.base");
  EXPECT_FALSE(fs::exists(folder_ / "qa"));
  Request r;
  r.previews = false;
  r.error_maps = true;
  run(shot, r);
  flicker(shot, "base", maps);
  ghost(shot, "base", maps);
  const fs::path qa = folder_ / "qa";
  for (const char* layer : {"base", "ink"})
    for (const char* f : {"frame_0000.png", "frame_0001.png", "frame_0002.png"})
      EXPECT_TRUE(fs::exists(qa / "error" / layer / f)) << layer << " " << f;
  for (const char* kind : {"flicker", "ghost"}) {
    EXPECT_FALSE(fs::exists(qa / kind / "base" / "frame_0000.png"));  // no frame before it
    EXPECT_TRUE(fs::exists(qa / kind / "base" / "frame_0002.png"));
  }
  const Image<float> error = io::read_image_float((qa / "error/base/frame_0001.png").string());
  double sum = 0;
  for (int y = 0; y < error.height(); ++y)
    for (int x = 0; x < error.width(); ++x) sum += error(x, y, 0) + error(x, y, 2);
  EXPECT_GT(sum, 0.0);
  const std::string flicker_map = test::file_bytes(qa / "flicker/base/frame_0001.png");
  const std::string ghost_map = test::file_bytes(qa / "ghost/base/frame_0002.png");
  const std::string error_map = test::file_bytes(qa / "error/ink/frame_0001.png");
  flicker(shot, "base", maps);
  ghost(shot, "base", maps);
  r.force = true;
  r.threads = 1;  // the maps do not depend on the thread count either
  run(shot, r);
  EXPECT_TRUE(test::file_bytes(qa / "flicker/base/frame_0001.png") == flicker_map);
  EXPECT_TRUE(test::file_bytes(qa / "ghost/base/frame_0002.png") == ghost_map);
  EXPECT_TRUE(test::file_bytes(qa / "error/ink/frame_0001.png") == error_map);
}

}  // namespace
}  // namespace emaki::shot
