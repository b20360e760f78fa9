#include "store/reference_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "render/passes.h"
#include "tests/test_dir.h"

namespace emaki::io {
namespace {

namespace fs = std::filesystem;

class ReferenceCache : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_dir("emaki_refs"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

Image<float> passes(int w, int h) {
  Image<float> im(w, h, render::kChannelCount);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < render::kChannelCount; ++c) im(x, y, c) = float(x * 3 + y * 5 + c) / 7;
  return im;
}

TEST_F(ReferenceCache, KeysFollowWhatTheRenderDependsOn) {
  pipeline::Exemplar e;
  const std::string key = reference_key(e, 40, 30);
  EXPECT_EQ(key.size(), 16u);
  EXPECT_EQ(reference_key(e, 40, 30), key);
  EXPECT_NE(reference_key(e, 41, 30), key);
  pipeline::Exemplar lit = e;
  lit.reference.light.softness_deg += 1;
  EXPECT_NE(reference_key(lit, 40, 30), key);
  pipeline::Exemplar aa = e;
  aa.aa += 1;
  EXPECT_NE(reference_key(aa, 40, 30), key);
}

TEST_F(ReferenceCache, KeptPassesReadBackExactlyAndOnlyWhenWhole) {
  const std::string out = dir_.string(), key = "0123456789abcdef";
  EXPECT_FALSE(read_reference(out, key, 9, 7).has_value());
  const Image<float> im = passes(9, 7);
  write_reference(out, key, im.cview());
  const std::optional<Image<float>> back = read_reference(out, key, 9, 7);
  ASSERT_TRUE(back.has_value());
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 9; ++x)
      for (int c = 0; c < render::kChannelCount; ++c) ASSERT_EQ((*back)(x, y, c), im(x, y, c));
  EXPECT_FALSE(read_reference(out, key, 9, 8).has_value());  // another painting size
  // Checked by header and size, as the pass cache is: 7 x 9 pixels under the key, as many bytes
  // as 9 x 7, are not read as 9 x 7.
  const fs::path pixels = dir_ / "references" / (key + ".passes");
  write_reference(out, key, passes(7, 9).cview());
  EXPECT_FALSE(read_reference(out, key, 9, 7).has_value());
  // The digest file earlier versions wrote beside the pixels is removed when they are written.
  std::ofstream(dir_ / "references" / (key + ".digest")) << "ffffffffffffffff\n";
  write_reference(out, key, im.cview());
  EXPECT_FALSE(fs::exists(dir_ / "references" / (key + ".digest")));
  EXPECT_TRUE(read_reference(out, key, 9, 7).has_value());
  // Cut short, or grown: not read (the file is mapped, so its size must be the image's).
  const auto size = fs::file_size(pixels);
  fs::resize_file(pixels, size - 4);
  EXPECT_FALSE(read_reference(out, key, 9, 7).has_value());
  fs::resize_file(pixels, size + 64);
  EXPECT_FALSE(read_reference(out, key, 9, 7).has_value());
  // The mapped image outlives nothing it needs: moved, it still reads.
  write_reference(out, key, im.cview());
  std::optional<Image<float>> kept = read_reference(out, key, 9, 7);
  ASSERT_TRUE(kept.has_value());
  Image<float> moved = std::move(*kept);
  kept.reset();
  EXPECT_EQ(moved(8, 6, render::kChannelCount - 1), im(8, 6, render::kChannelCount - 1));
}

}  // namespace
}  // namespace emaki::io
