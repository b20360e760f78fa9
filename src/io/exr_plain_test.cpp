// emaki's own EXR reader and writer (exr_plain.h) against OpenImageIO: what OpenImageIO writes
// (none, ZIPS, ZIP; float, half) is read the same, sample for sample and name for name; what
// emaki writes OpenImageIO reads as the image it was given (float exactly, half as OpenImageIO
// converts it); every other file is declined and read (or refused) as before.
#include "io/exr_plain.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "core/limits.h"
#include "io/exr_header.h"
#include "io/image_io.h"
#include "io/oiio_backend.h"
#include "tests/test_dir.h"

namespace emaki::io::detail {
namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kNames = {"normal.X", "normal.Y", "normal.Z", "depth.Y", "alpha.A"};

Image<float> pattern(int w, int h, int channels) {
  Image<float> im(w, h, channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) im(x, y, c) = float(x * 131 + y * 17 + c) / 7.f - 3;
  return im;
}

// Written by OpenImageIO (type 2 half, 3 float).
std::string oiio_write(const fs::path& dir, const std::string& name, const Image<float>& im,
                       const std::vector<std::string>& names, const char* compression,
                       int type = 3) {
  WriteOptions o;
  o.channel_names = names;
  o.compression = compression;
  const std::string path = (dir / name).string();
  const std::string e = oiio_backend(path).write(path, im.cview(), o, type);
  EXPECT_EQ(e, "");
  return path;
}

AnyImage oiio_read(const std::string& path, const std::vector<std::string>& names = {}) {
  AnyImage out;
  const std::string e = oiio_backend(path).read({path}, ReadOptions{names}, max_pixels(), out);
  EXPECT_EQ(e, "") << path;
  return out;
}

std::optional<AnyImage> plain(const std::string& path, const std::vector<std::string>& names) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  EXPECT_TRUE(f);
  return read_plain_exr(f.get(), path, names);
}

void expect_equal(const Image<float>& a, const Image<float>& b) {
  ASSERT_EQ(a.width(), b.width());
  ASSERT_EQ(a.height(), b.height());
  ASSERT_EQ(a.channels(), b.channels());
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < a.channels(); ++c) ASSERT_EQ(a(x, y, c), b(x, y, c)) << x << "," << y;
}

TEST(ExrPlain, ReadsWhatOpenImageIoWrites) {
  const test::TempDir scratch("exr_plain");
  const fs::path& dir = scratch.path();
  const Image<float> im = pattern(37, 23, int(kNames.size()));
  const std::vector<std::string> picked = {"depth.Y", "normal.X", "alpha.A", "normal.X"};
  for (const char* compression : {"none", "zips", "zip"})
    for (const int type : {2, 3}) {
      SCOPED_TRACE(std::string(compression) + (type == 2 ? " half" : " float"));
      const std::string path = oiio_write(dir, "p.exr", im, kNames, compression, type);
      const std::optional<AnyImage> fast = plain(path, picked);
      ASSERT_TRUE(fast);
      EXPECT_EQ(fast->channel_names, picked);
      expect_equal(fast->to_float(), oiio_read(path, picked).to_float());
    }
  // A whole-file read of a layer's channel sets: OpenImageIO's channels, in its order.
  for (const std::vector<std::string>& names : std::vector<std::vector<std::string>>{
           {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}}) {
    const std::string path =
        oiio_write(dir, "l.exr", pattern(9, 33, int(names.size())), names, "zip");
    const std::optional<AnyImage> fast = plain(path, {});
    ASSERT_TRUE(fast);
    const AnyImage slow = oiio_read(path);
    EXPECT_EQ(fast->channel_names, slow.channel_names);
    expect_equal(fast->to_float(), slow.to_float());
  }
}

TEST(ExrPlain, OpenImageIoReadsWhatEmakiWrites) {
  const test::TempDir scratch("exr_plain");
  const fs::path& dir = scratch.path();
  const Image<float> im = pattern(41, 35, int(kNames.size()));
  for (const char* compression : {"none", "zips", "zip"})
    for (const bool half : {true, false}) {
      SCOPED_TRACE(std::string(compression) + (half ? " half" : " float"));
      WriteOptions o;
      o.channel_names = kNames;
      o.compression = compression;
      o.attributes = {{"colorSpace", "ACEScg"}};
      o.chromaticities = {0.713f, 0.293f, 0.165f, 0.830f, 0.128f, 0.044f, 0.32168f, 0.33767f};
      const std::optional<std::string> bytes = encode_plain_exr(im.cview(), o, half);
      ASSERT_TRUE(bytes);
      const std::string path = (dir / "e.exr").string();
      std::ofstream(path, std::ios::binary).write(bytes->data(), std::streamsize(bytes->size()));
      check_exr_complete(reinterpret_cast<const unsigned char*>(bytes->data()), bytes->size(),
                         path);
      const Image<float> theirs = oiio_read(path, kNames).to_float();
      if (half)
        expect_equal(
            theirs,
            oiio_read(oiio_write(dir, "h.exr", im, kNames, compression, 2), kNames).to_float());
      else
        expect_equal(theirs, im);
      expect_equal(plain(path, kNames)->to_float(), theirs);
    }
  // Through write_image and read_image, as the store uses them.
  WriteOptions o;
  o.format = SampleFormat::kFloat;
  o.channel_names = kNames;
  write_image((dir / "w.exr").string(), im.cview(), o);
  expect_equal(read_image((dir / "w.exr").string(), ReadOptions{kNames}).to_float(), im);
  EXPECT_TRUE(image_file_complete((dir / "w.exr").string()));
}

TEST(ExrPlain, DeclinesOtherFilesWhichReadAsBefore) {
  const test::TempDir scratch("exr_plain");
  const fs::path& dir = scratch.path();
  Image<float> im = pattern(9, 5, int(kNames.size()));
  const std::string piz = oiio_write(dir, "piz.exr", im, kNames, "piz");
  EXPECT_FALSE(plain(piz, {"depth.Y"}));
  expect_equal(read_image(piz, ReadOptions{kNames}).to_float(), im);
  EXPECT_FALSE(plain(piz, {}));  // not a layer's channel set either
  const std::string none = oiio_write(dir, "none.exr", im, kNames, "none");
  EXPECT_FALSE(plain(none, {"normal.W"}));
  try {
    read_image(none, ReadOptions{{"normal.W"}});
    FAIL() << "a missing channel was read";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("no channel 'normal.W'"), std::string::npos) << e.what();
  }
  im(4, 3, 2) = std::numeric_limits<float>::quiet_NaN();
  for (const char* compression : {"none", "zip"}) {
    const std::string nan = oiio_write(dir, "nan.exr", im, kNames, compression);
    EXPECT_FALSE(plain(nan, kNames));
    EXPECT_THROW(read_image(nan, ReadOptions{kNames}), Error);
  }
  WriteOptions o;
  o.compression = "piz";
  o.channel_names = kNames;
  EXPECT_FALSE(encode_plain_exr(im.cview(), o, false));
  o.compression = "zip";
  o.channel_names = {};
  EXPECT_FALSE(encode_plain_exr(im.cview(), o, false));
}

TEST(ExrPlain, DeclinesDamagedFiles) {
  const test::TempDir scratch("exr_plain");
  const fs::path& dir = scratch.path();
  for (const char* compression : {"none", "zip"}) {
    SCOPED_TRACE(compression);
    const std::string good = oiio_write(dir, "good.exr", pattern(16, 40, 5), kNames, compression);
    std::ifstream in(good, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    // Cut short anywhere, or with bytes changed in the last chunk's y, byte count or data:
    // never read as plain. (The general reader refuses or reads such a file on its own terms;
    // exr_header_test covers it.)
    for (std::size_t cut :
         {bytes.size() - 1, bytes.size() / 2, std::size_t(400), std::size_t(20)}) {
      const std::string path = (dir / ("cut" + std::to_string(cut) + ".exr")).string();
      std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(cut));
      EXPECT_FALSE(plain(path, kNames)) << cut;
    }
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(good.c_str(), "rb"), &std::fclose);
    ASSERT_TRUE(read_plain_exr(f.get(), good, kNames));
    // The last chunk (of 16 rows, 5 float channels): its y and byte count uncompressed; the
    // last byte of its zlib stream (the checksum) under ZIP.
    const std::size_t last = bytes.size() - (8 + 16 * 5 * 4);
    const std::vector<std::size_t> edits = compression == std::string("zip")
                                               ? std::vector<std::size_t>{bytes.size() - 1}
                                               : std::vector<std::size_t>{last, last + 4};
    for (const std::size_t at : edits) {
      std::string edited = bytes;
      edited[at] = char(edited[at] + 1);
      const std::string path = (dir / ("edited" + std::to_string(at) + ".exr")).string();
      std::ofstream(path, std::ios::binary).write(edited.data(), std::streamsize(edited.size()));
      EXPECT_FALSE(plain(path, kNames)) << at;
    }
  }
}

}  // namespace
}  // namespace emaki::io::detail
