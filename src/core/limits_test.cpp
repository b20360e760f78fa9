// Error-line echoes (echo, echo_path) and the scoped pixel budget.
#include "core/limits.h"

#include <gtest/gtest.h>

#include <string>

namespace emaki {
namespace {

// True when `s` is well-formed UTF-8 (what Python's str() and JSON need).
bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const int n = c < 0x80 ? 0 : (c >> 5) == 6 ? 1 : (c >> 4) == 14 ? 2 : (c >> 3) == 30 ? 3 : -1;
    if (n < 0 || i + n >= s.size()) return false;
    for (int k = 1; k <= n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += n + 1;
  }
  return true;
}

TEST(Echo, ACutNeverSplitsAUtf8Character) {
  // Each cut position against characters of 2, 3 and 4 bytes.
  for (const std::string ch : {"\xc3\xa9", "\xe6\x97\xa5", "\xf0\x9f\x8e\xa8"})
    for (std::size_t lead = 0; lead < 4; ++lead) {
      std::string value(lead, 'a');
      for (int i = 0; i < 60; ++i) value += ch;
      const std::string out = echo(value);
      SCOPED_TRACE(out);
      EXPECT_TRUE(valid_utf8(out));
      const std::size_t kept = out.find("... (");
      ASSERT_NE(kept, std::string::npos);
      EXPECT_LE(kept, 80u);
      EXPECT_GT(kept, 80u - ch.size());
      EXPECT_EQ(out.substr(kept), "... (" + std::to_string(value.size()) + " bytes)");
    }
  EXPECT_EQ(echo("short \xc3\xa9"), "short \xc3\xa9");
  EXPECT_EQ(echo("tab\there"), "tab?here");
}

TEST(Echo, ALongPathKeepsWholeCharactersAtBothEnds) {
  std::string path = "/";
  for (int i = 0; i < 300; ++i) path += "\xe6\x97\xa5";  // 900 bytes
  path += "/frame.exr";
  for (std::size_t lead = 0; lead < 3; ++lead) {
    const std::string p = std::string(lead, 'a') + path;
    const std::string out = echo_path(p);
    SCOPED_TRACE(out);
    EXPECT_TRUE(valid_utf8(out));
    EXPECT_NE(out.find("...(" + std::to_string(p.size()) + " bytes)..."), std::string::npos);
    EXPECT_EQ(out.substr(out.size() - 10), "/frame.exr");
  }
}

TEST(PixelBudget, AScopedBudgetLastsWhileItLives) {
  EXPECT_EQ(max_pixels(), kDefaultMaxPixels);
  {
    const ScopedMaxPixels outer(1000);
    EXPECT_EQ(max_pixels(), 1000);
    EXPECT_THROW(check_pixel_budget("x", 40, 30), Error);
    {
      const ScopedMaxPixels inner(0);  // 0: unchanged
      EXPECT_EQ(max_pixels(), 1000);
    }
    EXPECT_EQ(scoped_max_pixels(), 1000);
  }
  EXPECT_EQ(max_pixels(), kDefaultMaxPixels);
  EXPECT_EQ(shot_max_pixels(0), kDefaultMaxPixels);
  EXPECT_EQ(shot_max_pixels(77), 77);
}

}  // namespace
}  // namespace emaki
