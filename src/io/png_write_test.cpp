// png_write.cpp on its own: the header it writes, clamping and rounding, the strips' zlib
// stream read back by zlib itself, and the inputs it refuses.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "io/png_io.h"

namespace emaki::io::detail {
namespace {

namespace fs = std::filesystem;

std::vector<unsigned char> written(ImageView<const float> image, bool sixteen_bit) {
  const fs::path path =
      fs::temp_directory_path() /
      ("emaki_png_write_" +
       std::to_string(::testing::UnitTest::GetInstance()->current_test_info()->line()) + ".png");
  write_png(path.string(), image, sixteen_bit, "out.png");
  std::ifstream f(path, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(f)), {});
  fs::remove(path);
  return bytes;
}

uint32_t be32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | p[3];
}

// The concatenated IDAT payloads, inflated with zlib (checks the Adler-32 the strips combine).
std::vector<unsigned char> inflated_pixels(const std::vector<unsigned char>& png,
                                           std::size_t expected) {
  std::vector<unsigned char> z;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const uint32_t n = be32(&png[at]);
    if (std::string(png.begin() + at + 4, png.begin() + at + 8) == "IDAT")
      z.insert(z.end(), png.begin() + at + 8, png.begin() + at + 8 + n);
    at += 12 + n;
  }
  std::vector<unsigned char> out(expected + 1);
  uLongf size = uLongf(out.size());
  EXPECT_EQ(uncompress(out.data(), &size, z.data(), uLong(z.size())), Z_OK);
  out.resize(size);
  return out;
}

TEST(PngWrite, HeaderNamesSizeDepthAndColourTypeForEachChannelCount) {
  const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  const int kColourType[5] = {0, 0, 4, 2, 6};  // grey, grey+alpha, RGB, RGBA
  for (int c = 1; c <= 4; ++c)
    for (bool sixteen : {false, true}) {
      const Image<float> im(5, 3, c);
      const std::vector<unsigned char> png = written(im.cview(), sixteen);
      ASSERT_GT(png.size(), 33u);
      EXPECT_TRUE(std::equal(kSignature, kSignature + 8, png.begin()));
      EXPECT_EQ(std::string(png.begin() + 12, png.begin() + 16), "IHDR");
      EXPECT_EQ(be32(&png[16]), 5u);
      EXPECT_EQ(be32(&png[20]), 3u);
      EXPECT_EQ(png[24], sixteen ? 16 : 8);
      EXPECT_EQ(png[25], kColourType[c]) << c << " channels";
      EXPECT_EQ(std::string(png.end() - 8, png.end() - 4), "IEND");
    }
}

TEST(PngWrite, ValuesAreClampedAndRoundedIntoTheStream) {
  Image<float> im(4, 1, 1);
  im(0, 0, 0) = -0.5f;
  im(1, 0, 0) = 1.5f;
  im(2, 0, 0) = 0.5f;
  im(3, 0, 0) = 1.0f / 255.0f;
  // One row: its filter byte, then the samples as the filter left them; inflate and undo it.
  const std::vector<unsigned char> raw = inflated_pixels(written(im.cview(), false), 5);
  ASSERT_EQ(raw.size(), 5u);
  std::vector<int> v(4);
  const int filter = raw[0];
  for (int x = 0; x < 4; ++x) {
    const int left = x > 0 ? v[x - 1] : 0;
    ASSERT_TRUE(filter == 0 || filter == 1 || filter == 2 || filter == 3 || filter == 4);
    // The first row has no row above: Up is None, Average is half of Left, Paeth is Left.
    const int pred = filter == 1 || filter == 4 ? left : filter == 3 ? left / 2 : 0;
    v[x] = (raw[1 + x] + pred) & 0xff;
  }
  EXPECT_EQ(v, (std::vector<int>{0, 255, 128, 1}));
}

TEST(PngWrite, RefusesWhatPngCannotHoldNamingTheSubject) {
  const Image<float> five_channels(2, 2, 5), empty;
  for (const Image<float>* bad : {&five_channels, &empty}) {
    try {
      written(bad->cview(), false);
      FAIL() << "written";
    } catch (const Error& e) {
      EXPECT_EQ(e.subject(), "out.png");
    }
  }
}

}  // namespace
}  // namespace emaki::io::detail
