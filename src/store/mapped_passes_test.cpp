// Mapped pass files: what is written maps back sample for sample, from a whole image or a view
// into a wider one; a file one byte short or long, or of another size, is not such a file; the
// mapped image is the process's own copy.
#include "store/mapped_passes.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "render/passes.h"
#include "tests/test_dir.h"

namespace emaki::io {
namespace {

namespace fs = std::filesystem;

class MappedPasses : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_dir("emaki_mapped_passes"); }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const char* name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

Image<float> passes(int w, int h) {
  Image<float> im(w, h, render::kChannelCount);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < render::kChannelCount; ++c)
        im(x, y, c) = float(x * 31 + y * 17 + c) / 13.0f - 2.0f;
  return im;
}

void expect_same(ImageView<const float> a, ImageView<const float> b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  ASSERT_EQ(a.channels, b.channels);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < a.channels; ++c) ASSERT_EQ(a(x, y, c), b(x, y, c)) << x << "," << y;
}

TEST_F(MappedPasses, AnImageMapsBackSampleForSample) {
  const Image<float> im = passes(37, 11);
  write_mapped_passes(file("a.passes"), im.cview());
  EXPECT_TRUE(mapped_passes_complete(file("a.passes"), 37, 11));
  const std::optional<Image<float>> back = map_passes(file("a.passes"), 37, 11);
  ASSERT_TRUE(back);
  expect_same(back->cview(), im.cview());
}

// A view whose rows lie further apart than the file pads them: written row by row.
TEST_F(MappedPasses, AViewIntoAWiderImageMapsBackSampleForSample) {
  const Image<float> wide = passes(90, 12);
  ImageView<const float> part = wide.cview();
  part.data = wide.cview().at(5, 1);
  part.width = 23;
  part.height = 9;
  write_mapped_passes(file("b.passes"), part);
  const std::optional<Image<float>> back = map_passes(file("b.passes"), 23, 9);
  ASSERT_TRUE(back);
  EXPECT_LT(back->cview().stride, part.stride);
  expect_same(back->cview(), part);
}

TEST_F(MappedPasses, OnlyAWholeFileOfTheSizeAskedForMaps) {
  const Image<float> im = passes(20, 7);
  const std::string path = file("c.passes");
  write_mapped_passes(path, im.cview());
  const auto size = fs::file_size(path);
  EXPECT_FALSE(mapped_passes_complete(path, 21, 7));
  EXPECT_FALSE(mapped_passes_complete(path, 20, 6));
  EXPECT_FALSE(map_passes(path, 21, 7));
  EXPECT_FALSE(mapped_passes_complete(file("missing.passes"), 20, 7));
  EXPECT_FALSE(map_passes(file("missing.passes"), 20, 7));
  ASSERT_EQ(::truncate(path.c_str(), off_t(size - 1)), 0);  // one byte short
  EXPECT_FALSE(mapped_passes_complete(path, 20, 7));
  EXPECT_FALSE(map_passes(path, 20, 7));
  ASSERT_EQ(::truncate(path.c_str(), off_t(size + 1)), 0);  // one byte long
  EXPECT_FALSE(mapped_passes_complete(path, 20, 7));
  EXPECT_FALSE(map_passes(path, 20, 7));
  ASSERT_EQ(::truncate(path.c_str(), off_t(size)), 0);
  EXPECT_TRUE(mapped_passes_complete(path, 20, 7));
  { std::ofstream(path, std::ios::in | std::ios::out | std::ios::binary).write("emkpass2", 8); }
  EXPECT_FALSE(mapped_passes_complete(path, 20, 7));  // another magic
  EXPECT_FALSE(map_passes(path, 20, 7));
}

TEST_F(MappedPasses, WritingToTheMappedImageLeavesTheFileAlone) {
  const Image<float> im = passes(16, 5);
  write_mapped_passes(file("d.passes"), im.cview());
  {
    std::optional<Image<float>> mine = map_passes(file("d.passes"), 16, 5);
    ASSERT_TRUE(mine);
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 16; ++x) (*mine)(x, y, 0) = 99.0f;
    EXPECT_EQ((*mine)(3, 2, 0), 99.0f);
  }
  const std::optional<Image<float>> again = map_passes(file("d.passes"), 16, 5);
  ASSERT_TRUE(again);
  expect_same(again->cview(), im.cview());
}

}  // namespace
}  // namespace emaki::io
