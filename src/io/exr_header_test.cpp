// exr_header.cpp on its own: a header emaki writes passes the walk; the same header cut short,
// or with a data window edited past the pixel budget, is refused naming the subject before
// OpenEXR would allocate from it.
#include "io/exr_header.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "io/image_io.h"

namespace emaki::io::detail {
namespace {

namespace fs = std::filesystem;

// A small float EXR as emaki writes it, as bytes.
std::vector<unsigned char> small_exr() {
  // One file per process: ctest runs this file's tests side by side.
  const fs::path path =
      fs::temp_directory_path() / ("emaki_exr_header_test_" + std::to_string(::getpid()) + ".exr");
  Image<float> im(6, 4, 3);
  WriteOptions o;
  o.format = SampleFormat::kFloat;
  write_image(path.string(), im.cview(), o);
  std::ifstream f(path, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(f)), {});
  fs::remove(path);
  return bytes;
}

// Where the value of attribute `name` (of `type`) starts: after name, type and size.
std::size_t attribute_value(const std::vector<unsigned char>& exr, const std::string& name,
                            const std::string& type) {
  std::string key = name;
  key.push_back('\0');
  key += type;
  key.push_back('\0');
  const auto at = std::search(exr.begin(), exr.end(), key.begin(), key.end());
  EXPECT_NE(at, exr.end()) << name;
  return std::size_t(at - exr.begin()) + key.size() + 4;
}

std::string refusal(const std::vector<unsigned char>& exr) {
  try {
    check_exr_header(exr.data(), exr.size(), "in.exr");
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "in.exr");
    return e.message();
  }
  return "";
}

TEST(ExrHeader, MagicNumberIsRecognised) {
  const std::vector<unsigned char> exr = small_exr();
  EXPECT_TRUE(has_exr_magic(exr.data(), exr.size()));
  const unsigned char png[4] = {0x89, 'P', 'N', 'G'};
  EXPECT_FALSE(has_exr_magic(png, 4));
  EXPECT_FALSE(has_exr_magic(exr.data(), 3));
}

TEST(ExrHeader, AHeaderEmakiWroteIsAccepted) {
  const std::vector<unsigned char> exr = small_exr();
  EXPECT_EQ(refusal(exr), "");
}

TEST(ExrHeader, EveryCutThroughTheHeaderIsRefused) {
  const std::vector<unsigned char> exr = small_exr();
  const std::size_t header_end = attribute_value(exr, "screenWindowWidth", "float") + 4;
  for (std::size_t n = 0; n < header_end; ++n) {
    const std::vector<unsigned char> cut(exr.begin(), exr.begin() + long(n));
    EXPECT_NE(refusal(cut), "") << "cut at " << n;
  }
}

TEST(ExrHeader, ADataWindowOverThePixelBudgetIsRefused) {
  std::vector<unsigned char> exr = small_exr();
  const std::size_t box = attribute_value(exr, "dataWindow", "box2i");
  const int32_t huge[4] = {0, 0, 1 << 30, 1 << 30};  // xMin, yMin, xMax, yMax
  std::memcpy(&exr[box], huge, sizeof huge);
  // Refused for its size, before the chunk table (too short for it as well) is looked at.
  const std::string why = refusal(exr);
  EXPECT_EQ(why.rfind("image size 1073741825x1073741825", 0), 0u) << why;
}

TEST(ExrHeader, AnEmptyDataWindowIsRefused) {
  std::vector<unsigned char> exr = small_exr();
  const std::size_t box = attribute_value(exr, "dataWindow", "box2i");
  const int32_t inverted[4] = {5, 0, 0, 3};  // xMax < xMin
  std::memcpy(&exr[box], inverted, sizeof inverted);
  EXPECT_NE(refusal(exr), "");
}

// OpenEXR reads a fixed-size type by its type and a channel list up to its empty name, whatever
// size the header gives them: a size that says otherwise would send it on another walk.
TEST(ExrHeader, AnAttributeWhoseSizeIsNotItsTypesIsRefused) {
  std::vector<unsigned char> exr = small_exr();
  const std::size_t width = attribute_value(exr, "screenWindowWidth", "float");
  const int32_t eight = 8;
  std::memcpy(&exr[width - 4], &eight, 4);
  EXPECT_EQ(refusal(exr),
            "EXR header: attribute 'screenWindowWidth' of type float has 8 bytes, not 4");
}

TEST(ExrHeader, AChannelListShorterThanItsAttributeIsRefused) {
  std::vector<unsigned char> exr = small_exr();
  const std::size_t list = attribute_value(exr, "channels", "chlist");
  int32_t size = 0;
  std::memcpy(&size, &exr[list - 4], 4);
  ++size;
  std::memcpy(&exr[list - 4], &size, 4);
  exr.insert(exr.begin() + long(list) + size - 1, 0);  // one byte after the list's end
  EXPECT_EQ(refusal(exr), "EXR header: channel list does not fill its attribute");
}

}  // namespace
}  // namespace emaki::io::detail
