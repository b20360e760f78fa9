#include <gtest/gtest.h>
TEST(Scene, Placeholder) { EXPECT_TRUE(true); }
