#include "core/resample.h"

#include <gtest/gtest.h>

#include <cmath>

namespace emaki {
namespace {

Image<float> ramp(int w, int h, int c) {
  Image<float> img(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int ch = 0; ch < c; ++ch) img(x, y, ch) = std::sin(0.7f * x + 1.3f * y + ch);
  return img;
}

double mean(const Image<float>& img, int ch) {
  double s = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) s += img(x, y, ch);
  return s / (double(img.width()) * img.height());
}

TEST(ResampleArea, HalvingAveragesEachTwoByTwoBlock) {
  const Image<float> in = ramp(8, 6, 2);
  const Image<float> out = resample_area(in.cview(), 4, 3);
  ASSERT_EQ(out.width(), 4);
  ASSERT_EQ(out.height(), 3);
  ASSERT_EQ(out.channels(), 2);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 2; ++c) {
        const float want = (in(2 * x, 2 * y, c) + in(2 * x + 1, 2 * y, c) +
                            in(2 * x, 2 * y + 1, c) + in(2 * x + 1, 2 * y + 1, c)) /
                           4;
        EXPECT_NEAR(out(x, y, c), want, 1e-6f);
      }
}

TEST(ResampleArea, SameSizeIsACopy) {
  const Image<float> in = ramp(7, 5, 3);
  const Image<float> out = resample_area(in.cview(), 7, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(out(x, y, c), in(x, y, c), 1e-6f);
}

TEST(ResampleArea, AnyFactorKeepsTheMeanAndAConstant) {
  const Image<float> in = ramp(37, 23, 3);
  for (auto [w, h] : {std::pair{18, 11}, {25, 16}, {1, 1}, {37, 7}}) {
    const Image<float> out = resample_area(in.cview(), w, h);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean(out, c), mean(in, c), 1e-5) << w << "x" << h;
  }
  Image<float> flat(13, 9, 1);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 13; ++x) flat(x, y) = 0.25f;
  const Image<float> out = resample_area(flat.cview(), 6, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) EXPECT_NEAR(out(x, y), 0.25f, 1e-6f);
}

}  // namespace
}  // namespace emaki
