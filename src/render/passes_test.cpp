// The passes' channel layout and names.
#include "render/passes.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace emaki::render {
namespace {

TEST(Passes, ChannelNamesMatchTheLayout) {
  const std::vector<std::string> names = channel_names();
  ASSERT_EQ(int(names.size()), kChannelCount);
  EXPECT_EQ(names[kNormal], "normal.X");
  EXPECT_EQ(names[kRestPosition + 2], "rest_position.Z");
  EXPECT_EQ(names[kMotion + 1], "motion.Y");
  EXPECT_EQ(names[kAlpha], "alpha.A");
}

}  // namespace
}  // namespace emaki::render
