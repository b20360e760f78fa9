// What one call sets stays with that call: shots run at once on different threads, each with its
// own thread count, beside a synthesis on all cores; a shot's `limits.max_pixels` governs that
// shot only (not the next shot parsed, nor anything after a shot that failed to parse).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "core/parallel.h"
#include "shot/api.h"
#include "synth/synthesizer.h"
#include "synth/test_images.h"
#include "tests/file_bytes.h"
#include "tests/small_painting.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

class ShotIsolation : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_shot_isolation_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    test::write_small_painting(kData + "/stylit/source_style.png", painting());
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string painting() const { return (dir_ / "pastel.png").string(); }

  // A tiny shot writing to dir_/<name>; `top` goes before [source], `size` is source.size.
  pipeline::Shot shot(const std::string& name, const std::string& top = "",
                      const std::string& size = "[40, 24]") const {
    const std::string text =
        top + "\n[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\n" +
        "frames = [0, 2]\nsize = " + size + "\naa = 1\n[exemplars.sphere]\npainting = \"" +
        painting() + "\"\n[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n" +
        "[outputs]\nfolder = \"" + (dir_ / name).string() + "\"\nmp4 = false\n" +
        "contact_sheet = false\n";
    return open_text(text, (dir_ / (name + ".toml")).string());
  }
  std::string composite_bytes(const std::string& name) const {
    return test::file_bytes(dir_ / name / "composite" / "frame_0002.png");
  }

  fs::path dir_;
};

synth::Result small_synthesis() {
  synth::Inputs in;
  const Image<float> style = synth::test::noise(48, 40, 3, 1);
  const Image<float> src = synth::test::textured(48, 40, 2), tgt = synth::test::textured(56, 36, 3);
  in.style = style.cview();
  in.guides.push_back({"g", src.cview(), tgt.cview(), 1.0f});
  return synth::synthesize(in, synth::Params{});
}

// Each shot run used to reset the process-wide task arena while the other thread's work ran in
// it: a crash in oneTBB. Now each call has its own arena; results do not change.
TEST_F(ShotIsolation, ShotsAndASynthesisRunAtOnceWithTheirOwnThreadCounts) {
  const pipeline::Shot a = shot("a"), b = shot("b");
  Request alone;
  alone.threads = 1;
  run(a, alone);
  const std::string expected = composite_bytes("a");
  ASSERT_FALSE(expected.empty());
  const synth::Result synth_expected = small_synthesis();

  constexpr int kRuns = 6;
  std::atomic<int> shots_running{2};
  std::vector<std::string> failures(3);
  auto shot_loop = [&](const pipeline::Shot& s, const std::string& name, int threads, int slot) {
    try {
      for (int i = 0; i < kRuns; ++i) {
        Request r;
        r.threads = threads + i % 2;
        r.force = true;
        run(s, r);
        if (composite_bytes(name) != expected) failures[slot] = name + ": output differs";
      }
    } catch (const std::exception& e) {
      failures[slot] = e.what();
    }
    --shots_running;
  };
  std::thread ta(shot_loop, std::cref(a), "a", 1, 0);
  std::thread tb(shot_loop, std::cref(b), "b", 2, 1);
  std::thread tc([&] {
    int rounds = 0;
    while (shots_running > 0 || rounds == 0) {
      const ScopedThreadCount all(0);
      const synth::Result r = small_synthesis();
      if (!synth::test::same_bits(r.image, synth_expected.image)) failures[2] = "synthesis differs";
      ++rounds;
    }
  });
  ta.join();
  tb.join();
  tc.join();
  for (const std::string& f : failures) EXPECT_EQ(f, "");
}

// `emaki plan a.toml b.toml`, or two Shot objects in Python: a's budget is a's alone.
TEST_F(ShotIsolation, AShotsPixelBudgetStaysWithThatShot) {
  // 1.2 M pixels: a's own 40x24 frames and 100x76 painting fit; b's 1200x1100 frames do not.
  const pipeline::Shot a = shot("a", "[limits]\nmax_pixels = 1200000");
  EXPECT_EQ(a.max_pixels, 1200000);
  EXPECT_EQ(max_pixels(), kDefaultMaxPixels);
  EXPECT_NO_THROW(shot("b", "", "[1200, 1100]"));
  // And the shot's own budget still holds for its own frames.
  EXPECT_THROW(shot("c", "[limits]\nmax_pixels = 1200000", "[1200, 1100]"), Error);
}

TEST_F(ShotIsolation, AShotThatFailedOnItsBudgetLeavesNoBudgetBehind) {
  try {
    shot("a", "[limits]\nmax_pixels = 1");
    ADD_FAILURE() << "a 1-pixel budget accepted 40x24 frames";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "source.size");
  }
  EXPECT_EQ(max_pixels(), kDefaultMaxPixels);
  EXPECT_NO_THROW(check_pixel_budget("later", 1000, 1000));
  EXPECT_NO_THROW(shot("b"));
}

// The budget holds for the shot's whole work, also on the workers of its parallel loops.
TEST_F(ShotIsolation, AShotsBudgetHoldsDuringItsWork) {
  const pipeline::Shot s = shot("a", "[limits]\nmax_pixels = 5000");  // under the painting's 7600
  try {
    run(s, Request{});
    ADD_FAILURE() << "a 100x76 painting read under a 5000-pixel budget";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pixel budget of 5000"), std::string::npos) << e.what();
  }
  EXPECT_EQ(max_pixels(), kDefaultMaxPixels);
  std::atomic<int64_t> seen{0};
  std::atomic<int> other_threads{0};
  {
    const ScopedThreadCount two(2);
    const ScopedMaxPixels scope(5000);
    const std::thread::id caller = std::this_thread::get_id();
    parallel_for(64, 1, [&](int64_t, int64_t) {
      // Long enough a chunk for the worker to take some of them.
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      other_threads += std::this_thread::get_id() != caller;
      if (max_pixels() != 5000) seen = max_pixels();
    });
  }
  EXPECT_EQ(seen, 0);
  if (other_threads == 0) GTEST_SKIP() << "no chunk ran on a worker";
}

}  // namespace
}  // namespace emaki::shot
