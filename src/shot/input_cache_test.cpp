// The input cache (emaki lookdev's runs after a save): a run with it (and the error maps lookdev
// asks for) writes what a fresh run without either writes, byte for byte, after the painting
// changed; what the painting's old version left in the cache is dropped.
#include "shot/input_cache.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "io/image_io.h"
#include "render/passes.h"
#include "shot/api.h"
#include "shot/inputs.h"
#include "tests/file_bytes.h"
#include "tests/small_painting.h"
#include "tests/test_dir.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

class InputCacheRun : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_test_dir("emaki_input_cache");
    test::write_small_painting(kData + "/stylit/source_style.png", painting());
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string painting() const { return (dir_ / "pastel.png").string(); }

  // Two frames, every layer frame by frame (as lookdev runs them), a paper to composite over.
  pipeline::Shot shot(const std::string& out) const {
    const std::string text =
        "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\n" +
        "frames = [0, 1]\nsize = [40, 24]\naa = 1\n[exemplars.sphere]\npainting = \"" + painting() +
        "\"\n[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n" +
        "temporal = false\n[layers.ink]\nkind = \"outline\"\nexemplar = \"sphere\"\n" +
        "temporal = false\n[compositing]\npaper = \"" + kData + "/papers/roughpaper.png\"\n" +
        "[outputs]\nfolder = \"" + (dir_ / out).string() + "\"\nmp4 = false\n";
    return open_text(text, (dir_ / "shot.toml").string());
  }
  // As lookdev asks for it (with the error maps, which do not change the frame), or not.
  static Request frame(int f, bool as_lookdev = true) {
    Request r;
    r.first_frame = r.last_frame = f;
    r.force = true;
    r.previews = false;
    r.error_maps = as_lookdev;
    return r;
  }

  // Every file a run of frame 1 writes that a viewer shows, equal in both folders.
  void expect_same_frame(const std::string& a, const std::string& b) const {
    for (const char* f :
         {"layers/base/base_0001.exr", "layers/ink/ink_0001.exr", "layers/base/base_0001.png",
          "composite/frame_0001.png", "layered/frame_0001.exr"}) {
      SCOPED_TRACE(f);
      const std::string x = test::file_bytes(dir_ / a / f), y = test::file_bytes(dir_ / b / f);
      ASSERT_FALSE(x.empty());
      EXPECT_TRUE(x == y);
    }
  }

  fs::path dir_;
};

TEST_F(InputCacheRun, ARunAfterASaveOfThePaintingEqualsAFreshRun) {
  InputCache cache;
  run(shot("kept"), frame(1), cache);
  const std::size_t held = cache.size();
  EXPECT_GE(held, 3u);  // the painting, its reference passes, the paper (and frame 1's passes)
  // The painting saved with other strokes: a smaller copy of another picture, same size.
  test::write_small_painting(kData + "/stylit/source_fullgi.png", painting());
  run(shot("kept"), frame(1), cache);
  EXPECT_EQ(cache.size(), held);  // the old painting is gone, the new one took its place
  run(shot("fresh"), frame(1, false));
  expect_same_frame("kept", "fresh");
}

TEST_F(InputCacheRun, ARunWithTheCacheEqualsOneWithout) {
  InputCache cache;
  run(shot("kept"), frame(1), cache);
  run(shot("kept"), frame(1), cache);  // everything from the cache this time
  run(shot("fresh"), frame(1, false));
  expect_same_frame("kept", "fresh");
}

// A painted key frame over a pass file: the guides cut from the file are kept under its digest,
// so a pass file saved again (another frame's passes) is read again.
TEST_F(InputCacheRun, ARunAfterASaveOfThePassFileEqualsAFreshRun) {
  const std::string passes = (dir_ / "key.exr").string();
  const auto write_passes = [&](int frame) {
    const Image<float> p = open_frames(shot("scene"))->passes(frame);
    io::WriteOptions exr;
    exr.format = io::SampleFormat::kFloat;
    exr.channel_names = render::channel_names();
    io::write_image(passes, p.cview(), exr);
  };
  test::write_small_painting(kData + "/stylit/source_style.png", painting(), 40, 24);
  const auto keyframe = [&](const std::string& out) {
    const std::string text =
        "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\n" +
        "frames = [0, 1]\nsize = [40, 24]\naa = 1\n[exemplars.key]\nkind = \"keyframe\"\n" +
        "painting = \"" + painting() + "\"\npasses = \"" + passes + "\"\n[layers.base]\n" +
        "kind = \"base\"\nexemplar = \"key\"\ntemporal = false\n[outputs]\nfolder = \"" +
        (dir_ / out).string() + "\"\nmp4 = false\n";
    return open_text(text, (dir_ / "key.toml").string());
  };
  write_passes(0);
  InputCache cache;
  run(keyframe("kept"), frame(1), cache);
  write_passes(1);
  run(keyframe("kept"), frame(1), cache);
  run(keyframe("fresh"), frame(1, false));
  for (const char* f : {"layers/base/base_0001.exr", "composite/frame_0001.png"}) {
    SCOPED_TRACE(f);
    const std::string x = test::file_bytes(dir_ / "kept" / f),
                      y = test::file_bytes(dir_ / "fresh" / f);
    ASSERT_FALSE(x.empty());
    EXPECT_TRUE(x == y);
  }
}

}  // namespace
}  // namespace emaki::shot
