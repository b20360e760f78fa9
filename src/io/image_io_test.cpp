// Round trips through image files, and the errors that name the file.
#include "io/image_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/error.h"

namespace fs = std::filesystem;

namespace emaki::io {
namespace {

class ImageIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_io_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string p(const std::string& n) const { return (dir_ / n).string(); }
  fs::path dir_;
};

Image<float> ramp(int w, int h, int c, int levels) {
  Image<float> im(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k)
        im(x, y, k) = float((x * 7 + y * 13 + k * 101) % levels) / float(levels - 1);
  return im;
}

TEST_F(ImageIo, Png8BitRoundTripIsExact) {
  for (int c = 1; c <= 4; ++c) {
    const Image<float> im = ramp(37, 21, c, 256);
    WriteOptions o;
    o.format = SampleFormat::kU8;
    write_image(p("a.png"), im.cview(), o);
    const AnyImage back = read_image(p("a.png"));
    ASSERT_EQ(back.type(), PixelType::kU8);
    ASSERT_EQ(back.channels(), c);
    for (int y = 0; y < 21; ++y)
      for (int x = 0; x < 37; ++x)
        for (int k = 0; k < c; ++k)
          ASSERT_EQ(std::get<Image<uint8_t>>(back.image)(x, y, k),
                    std::lround(im(x, y, k) * 255.0f));
  }
}

TEST_F(ImageIo, Png16BitRoundTripIsExact) {
  const Image<float> im = ramp(40, 30, 3, 65536);
  write_image(p("a.png"), im.cview());  // PNG defaults to 16-bit
  const AnyImage back = read_image(p("a.png"));
  ASSERT_EQ(back.type(), PixelType::kU16);
  for (int y = 0; y < 30; ++y)
    for (int x = 0; x < 40; ++x)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(std::get<Image<uint16_t>>(back.image)(x, y, k),
                  std::lround(im(x, y, k) * 65535.0f));
}

TEST_F(ImageIo, FloatExrRoundTripIsExactWithNamedChannels) {
  Image<float> im(19, 11, 3);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 19; ++x)
      for (int k = 0; k < 3; ++k) im(x, y, k) = -3.25f + 0.001f * float(x + 19 * y) + 10.0f * k;
  WriteOptions o;
  o.format = SampleFormat::kFloat;
  o.channel_names = {"position.X", "position.Y", "position.Z"};
  write_image(p("a.exr"), im.cview(), o);
  const AnyImage back = read_image(p("a.exr"));
  ASSERT_EQ(back.type(), PixelType::kF32);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 19; ++x)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(back.value(x, y, k), im(x, y, k));
  ReadOptions pick;
  pick.channels = {"position.Z", "position.X"};
  const Image<float> two = read_image_float(p("a.exr"), pick);
  ASSERT_EQ(two.channels(), 2);
  EXPECT_EQ(two(5, 4, 0), im(5, 4, 2));
  EXPECT_EQ(two(5, 4, 1), im(5, 4, 0));
}

TEST_F(ImageIo, HalfExrKeepsHalfPrecision) {
  const Image<float> im = ramp(16, 8, 1, 1024);
  write_image(p("h.exr"), im.cview());  // EXR defaults to half
  const AnyImage back = read_image(p("h.exr"));
  for (int x = 0; x < 16; ++x) EXPECT_NEAR(back.value(x, 3, 0), im(x, 3), 1e-3f);
}

TEST_F(ImageIo, MissingChannelListsWhatTheFileHas) {
  Image<float> im(4, 4, 2);
  WriteOptions o;
  o.channel_names = {"motion.X", "motion.Y"};
  write_image(p("m.exr"), im.cview(), o);
  ReadOptions pick;
  pick.channels = {"normal.X"};
  try {
    read_image(p("m.exr"), pick);
    FAIL();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("m.exr"), std::string::npos);
    EXPECT_NE(msg.find("normal.X"), std::string::npos);
    EXPECT_NE(msg.find("motion.Y"), std::string::npos);
  }
}

TEST_F(ImageIo, NanInExrIsRejected) {
  Image<float> im(4, 4, 1);
  im(2, 1) = std::numeric_limits<float>::infinity();
  WriteOptions o;
  o.format = SampleFormat::kFloat;
  write_image(p("n.exr"), im.cview(), o);
  EXPECT_THROW(read_image(p("n.exr")), Error);
}

TEST_F(ImageIo, CorruptAndMissingFilesNameTheFile) {
  std::ofstream(p("c.png"), std::ios::binary) << "\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
  for (const std::string f : {p("c.png"), p("missing.png")}) {
    try {
      read_image(f);
      FAIL() << f;
    } catch (const Error& e) {
      EXPECT_EQ(e.subject(), f);
    }
  }
}

TEST_F(ImageIo, FailedWriteLeavesNothingBehind) {
  Image<float> im(4, 4, 3);
  EXPECT_THROW(write_image(p("nofolder/x.png"), im.cview()), Error);
  EXPECT_THROW(write_image(p("x.bmpx"), im.cview()), Error);
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace emaki::io
