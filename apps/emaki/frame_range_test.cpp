// The `--frames` parser every command shares: what it accepts and what it refuses.
#include "apps/emaki/frame_range.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "core/limits.h"

namespace emaki::app {
namespace {

TEST(FrameRange, AcceptsRangeAndSingleFrame) {
  FrameRange r = parse_frame_range("--frames", "0-47");
  EXPECT_EQ(r.first, 0);
  EXPECT_EQ(r.last, 47);
  r = parse_frame_range("--frames", "12");
  EXPECT_EQ(r.first, 12);
  EXPECT_EQ(r.last, 12);
  r = parse_frame_range("--frames", "5-5");
  EXPECT_EQ(r.first, 5);
  EXPECT_EQ(r.last, 5);
}

TEST(FrameRange, AcceptsTheLimits) {
  const std::string top = std::to_string(kMaxFrame);
  FrameRange r = parse_frame_range("--frames", top);
  EXPECT_EQ(r.first, kMaxFrame);
  EXPECT_EQ(r.last, kMaxFrame);
  r = parse_frame_range("--frames", "0-" + std::to_string(kMaxFrameCount - 1));
  EXPECT_EQ(r.last - r.first + 1, kMaxFrameCount);
}

TEST(FrameRange, RefusesAndNamesTheOption) {
  const std::string over_count = "0-" + std::to_string(kMaxFrameCount);
  const std::string over_frame = std::to_string(kMaxFrame + 1);
  for (const std::string& bad : {std::string(""),
                                 std::string("-"),
                                 std::string("-1"),
                                 std::string("-1-2"),
                                 std::string("3-"),
                                 std::string("5-4"),
                                 std::string("a"),
                                 std::string("0-x"),
                                 std::string("1.5"),
                                 std::string(" 1"),
                                 std::string("+1"),
                                 std::string("1 "),
                                 std::string("1-2-3"),
                                 std::string("0--2"),
                                 std::string("0-4294967297"),
                                 std::string("99999999999"),
                                 std::string("0-99999999999999999999"),
                                 std::string("2147483647"),
                                 over_count,
                                 over_frame}) {
    SCOPED_TRACE(bad);
    try {
      parse_frame_range("--frames", bad);
      ADD_FAILURE() << "accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.subject(), "--frames");
      EXPECT_NE(std::string(e.what()).find("FIRST-LAST or FRAME"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace emaki::app
