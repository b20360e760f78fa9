#include <gtest/gtest.h>
TEST(ReferenceSphere, Placeholder) { EXPECT_TRUE(true); }
