// Round trips through image files, and the errors that name the file.
#include "io/image_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "io/read_limits.h"

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

std::string file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

// PNG is written in strips of rows deflated in parallel (png_write.cpp). Images of many strips,
// every channel count and both depths must read back exactly (through libpng), and the file must
// be byte for byte the same for any thread count.
TEST_F(ImageIo, PngInManyStripsRoundTripsAndIgnoresThreadCount) {
  for (const bool sixteen : {false, true})
    for (int c = 1; c <= 4; ++c) {
      SCOPED_TRACE(std::to_string(c) + (sixteen ? " channels, 16-bit" : " channels, 8-bit"));
      // 300 wide: 301-2401 bytes a row, so 1300 rows make 2-12 strips of 2^18 bytes.
      Image<float> im = ramp(300, 1300, c, sixteen ? 65536 : 256);
      for (int x = 0; x < 300; x += 3) im(x, 700, 0) = -1.0f;  // clamped to 0
      for (int x = 1; x < 300; x += 3) im(x, 701, 0) = 2.0f;   // clamped to 1
      WriteOptions o;
      o.format = sixteen ? SampleFormat::kU16 : SampleFormat::kU8;
      std::string first;
      for (int threads : {1, 2, 3}) {
        const ScopedThreadCount count(threads);
        write_image(p("s.png"), im.cview(), o);
        const std::string bytes = file_bytes(p("s.png"));
        if (first.empty()) first = bytes;
        EXPECT_EQ(bytes, first) << threads << " threads";
      }
      const AnyImage back = read_image(p("s.png"));
      ASSERT_EQ(back.channels(), c);
      ASSERT_EQ(back.width(), 300);
      ASSERT_EQ(back.height(), 1300);
      for (int y = 0; y < 1300; ++y)
        for (int x = 0; x < 300; ++x)
          for (int k = 0; k < c; ++k) {
            const float v = std::clamp(im(x, y, k), 0.0f, 1.0f);
            if (sixteen)
              ASSERT_EQ(std::get<Image<uint16_t>>(back.image)(x, y, k), std::lround(v * 65535.0f));
            else
              ASSERT_EQ(std::get<Image<uint8_t>>(back.image)(x, y, k), std::lround(v * 255.0f));
          }
    }
}

// Wider than libpng (and so emaki's reader) accepts: refused by name, nothing left behind.
TEST_F(ImageIo, PngWiderThanLibpngReadsIsRefused) {
  const Image<float> im(1000001, 1, 1);
  try {
    write_image(p("wide.png"), im.cview());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), p("wide.png"));
    EXPECT_NE(std::string(e.what()).find("limited to 1000000 pixels"), std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::is_empty(dir_));
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

// The first plugin found is the one: when it cannot load, the error says why (here: not a shared
// object; in an install, the library it needs that is missing) instead of another build's plugin
// loading silently. In a fresh process ("threadsafe" death test): the plugin is loaded once per
// process.
TEST_F(ImageIo, APluginThatCannotLoadIsTheErrorNotAFallBack) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const std::string plugin = p("libemaki_io_oiio.so"), exr = p("a.exr");
  std::ofstream(plugin) << "not a shared object\n";
  EXPECT_EXIT(
      {
        ::setenv("EMAKI_OIIO_MODULE", plugin.c_str(), 1);
        int code = 0;
        try {
          WriteOptions o;
          o.format = SampleFormat::kHalf;
          write_image(exr, ramp(4, 3, 3, 7).cview(), o);
        } catch (const Error& e) {
          std::fprintf(stderr, "%s\n", e.what());
          code = fs::exists(exr) ? 4 : 3;
        }
        fs::remove_all(dir_);
        std::exit(code);
      },
      ::testing::ExitedWithCode(3), "cannot load the OpenImageIO plugin .*libemaki_io_oiio.so");
}

// Named channels are read from one decoding of their part, a band of rows at a time: every
// compression, an image taller than a band and not a whole number of them, channels asked for
// in another order than the file's, a cheap intermediate compression.
TEST_F(ImageIo, NamedChannelsOfATallImageReadExactlyInAnyOrder) {
  const Image<float> im = ramp(23, 150, 5, 977);
  const std::vector<std::string> names = {"a.X", "b.Y", "c", "d.Z", "e"};
  for (const char* compression : {"zip", "none", "rle", "zips", "piz"}) {
    SCOPED_TRACE(compression);
    WriteOptions o;
    o.format = SampleFormat::kFloat;
    o.channel_names = names;
    o.compression = compression;
    write_image(p("t.exr"), im.cview(), o);
    const Image<float> back = read_image_float(p("t.exr"), ReadOptions{{"e", "b.Y", "a.X", "d.Z"}});
    ASSERT_EQ(back.channels(), 4);
    const int from[4] = {4, 1, 0, 3};
    for (int y = 0; y < im.height(); ++y)
      for (int x = 0; x < im.width(); ++x)
        for (int k = 0; k < 4; ++k) ASSERT_EQ(back(x, y, k), im(x, y, from[k])) << x << "," << y;
  }
}

// The pass cache's read: a whole file is read (in one open), one cut short or missing is not.
TEST_F(ImageIo, ReadIfCompleteReadsWholeFilesOnly) {
  const Image<float> im = ramp(17, 70, 3, 101);
  WriteOptions o;
  o.format = SampleFormat::kFloat;
  write_image(p("w.exr"), im.cview(), o);
  const std::optional<AnyImage> whole = read_image_if_complete(p("w.exr"));
  ASSERT_TRUE(whole.has_value());
  EXPECT_EQ(whole->value(3, 60, 2), im(3, 60, 2));
  EXPECT_FALSE(read_image_if_complete(p("none.exr")).has_value());
  std::ifstream in(p("w.exr"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(p("cut.exr"), std::ios::binary)
      .write(bytes.data(), std::streamsize(bytes.size() - 5));
  EXPECT_FALSE(read_image_if_complete(p("cut.exr")).has_value());
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
  for (const std::string& f : {p("c.png"), p("missing.png")}) {
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

// ---------------------------------------------------------------------------------------------
// Hostile input (issue 9): the readers check what a header claims before allocating.

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

// Every seed of the fuzz corpora is a valid file (8/16-bit, gray to RGBA, palette, interlaced
// PNG; half/float/uint, scanline/tiled/mipmapped, multilayer and multipart EXR in each
// compression): the header walks must accept them all, and memory reads must match file reads.
TEST_F(ImageIo, EveryFuzzSeedReadsTheSameFromFileAndMemory) {
  int files = 0;
  for (const char* folder : {"png", "exr"})
    for (const auto& e :
         fs::directory_iterator(fs::path(EMAKI_SOURCE_DIR) / "fuzz" / "corpus" / folder)) {
      SCOPED_TRACE(e.path().string());
      const AnyImage a = read_image(e.path().string());
      const std::string bytes = slurp(e.path().string());
      const AnyImage b = read_image_memory(bytes.data(), bytes.size(), e.path().string());
      ASSERT_GT(a.width(), 0);
      ASSERT_EQ(a.width(), b.width());
      ASSERT_EQ(a.height(), b.height());
      ASSERT_EQ(a.channels(), b.channels());
      ASSERT_EQ(a.channel_names, b.channel_names);
      for (int y = 0; y < a.height(); ++y)
        for (int x = 0; x < a.width(); ++x)
          for (int c = 0; c < a.channels(); ++c) ASSERT_EQ(a.value(x, y, c), b.value(x, y, c));
      // Every part's channels, the first part's first (a multipart file has more).
      const std::vector<std::string> listed = list_channels(e.path().string());
      ASSERT_GE(listed.size(), a.channel_names.size());
      EXPECT_TRUE(std::equal(a.channel_names.begin(), a.channel_names.end(), listed.begin()));
      ++files;
    }
  EXPECT_GE(files, 20);
}

// What the output store asks before it counts a frame finished: every valid seed (scanline,
// tiled, mipmapped, multipart EXR; PNG) is whole, and the same file cut short by a byte, or to
// half, is not (a mipmapped file's lower levels excepted: their chunks are not listed).
TEST_F(ImageIo, EveryFuzzSeedIsCompleteAndNotWhenCutShort) {
  int cut = 0;
  for (const char* folder : {"png", "exr"})
    for (const auto& e :
         fs::directory_iterator(fs::path(EMAKI_SOURCE_DIR) / "fuzz" / "corpus" / folder)) {
      SCOPED_TRACE(e.path().string());
      const std::string name = e.path().filename().string();
      const std::string bytes = slurp(e.path().string());
      EXPECT_TRUE(image_file_complete(e.path().string()));
      if (name.find("mip") != std::string::npos) continue;
      for (std::size_t keep : {bytes.size() - 1, bytes.size() / 2}) {
        const std::string copy = p(name);
        std::ofstream(copy, std::ios::binary).write(bytes.data(), std::streamsize(keep));
        EXPECT_FALSE(image_file_complete(copy)) << keep;
        ++cut;
      }
    }
  EXPECT_GE(cut, 30);
}

// A pixel count within the budget is not enough: Image pads each row to 64 bytes, so a
// 1 x 2^28 image would take 16 GiB.
TEST(ReadLimits, RowPaddingCountsAgainstTheBudget) {
  EXPECT_THROW(detail::check_image_alloc<uint8_t>("f", 1, int64_t(1) << 28, 1), Error);
  EXPECT_NO_THROW(detail::check_image_alloc<float>("f", 4096, 4096, 4));
  EXPECT_THROW(detail::check_image_alloc<float>("f", 4, 4, 65), Error);
  try {
    detail::check_image_alloc<uint8_t>("in.png", 100000, 100000, 3);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "in.png");
  }
}

// libpng fails after the image is allocated (2 of 2000 rows present): the error names the file
// and, under the asan preset, LeakSanitizer checks at exit that the image was freed.
// Every hostile reproducer is an error from memory as from a file (the shot reads its inputs'
// bytes once and decodes them from memory): read_before_start.exr made OpenImageIO's own memory
// reader copy from before the buffer, which AddressSanitizer reports here.
TEST_F(ImageIo, EveryHostileFileIsAnErrorFromMemoryToo) {
  int files = 0;
  for (const char* folder : {"png", "exr"})
    for (const auto& e : fs::directory_iterator(fs::path(EMAKI_SOURCE_DIR) / "tests" / "data" /
                                                "hostile" / folder)) {
      // Within the pixel budget but 3 GB as float: tests/hostile_image_test.cpp reads it under
      // an address-space bound.
      if (e.path().filename() == "window_16000x16000.exr") continue;
      SCOPED_TRACE(e.path().string());
      const std::string bytes = slurp(e.path().string());
      EXPECT_THROW(read_image(e.path().string()), Error);
      EXPECT_THROW(read_image_memory(bytes.data(), bytes.size(), e.path().string()), Error);
      ++files;
    }
  EXPECT_GE(files, 20);
}

TEST_F(ImageIo, PngWithTooFewRowsNamesTheFile) {
  const int w = 2000;
  std::string raw;
  for (int y = 0; y < 2; ++y) raw += '\0' + std::string(std::size_t(w), char(y));
  // zlib of raw in one stored deflate block (raw is under 65535 bytes).
  std::string z = "\x78\x01\x01";
  const uint16_t n = uint16_t(raw.size());
  z += {char(n & 0xff), char(n >> 8), char(~n & 0xff), char((~n >> 8) & 0xff)};
  z += raw;
  uint32_t a = 1, b = 0;
  for (unsigned char c : raw) a = (a + c) % 65521, b = (b + a) % 65521;
  const uint32_t adler = b << 16 | a;
  z += {char(adler >> 24), char(adler >> 16), char(adler >> 8), char(adler)};
  auto be32 = [](uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  auto crc = [](const std::string& s) {
    uint32_t c = 0xffffffffu;
    for (unsigned char ch : s) {
      c ^= ch;
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return ~c;
  };
  auto chunk = [&](const std::string& type, const std::string& data) {
    return be32(uint32_t(data.size())) + type + data + be32(crc(type + data));
  };
  const std::string png = std::string("\x89PNG\r\n\x1a\n", 8) +
                          chunk("IHDR", be32(w) + be32(w) + std::string{8, 0, 0, 0, 0}) +
                          chunk("IDAT", z) + chunk("IEND", "");
  std::ofstream(p("short.png"), std::ios::binary) << png;
  try {
    read_image(p("short.png"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), p("short.png"));
    EXPECT_NE(std::string(e.what()).find("Not enough image data"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_image_memory(png.data(), png.size(), "short.png"), Error);
}

TEST_F(ImageIo, OnlyDocumentedFormatsAreReadThroughOpenImageIo) {
  // A real TIFF named .hdr is not handed to OpenImageIO's other readers.
  const Image<float> im = ramp(4, 4, 3, 256);
  write_image(p("a.tif"), im.cview());
  EXPECT_EQ(read_image(p("a.tif")).width(), 4);
  fs::copy_file(p("a.tif"), p("a.hdr"));
  try {
    read_image(p("a.hdr"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), p("a.hdr"));
    EXPECT_NE(std::string(e.what()).find("unsupported image format"), std::string::npos);
  }
}

}  // namespace
}  // namespace emaki::io
