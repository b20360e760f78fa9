#include "composite/composite.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "core/error.h"

namespace emaki::composite {
namespace {

Image<float> constant(int w, int h, std::vector<float> v) {
  Image<float> img(w, h, int(v.size()));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < int(v.size()); ++c) img(x, y, c) = v[c];
  return img;
}

TEST(Composite, BlendModesOnKnownValues) {
  EXPECT_FLOAT_EQ(blend(BlendMode::kNormal, 0.2f, 0.7f), 0.7f);
  EXPECT_FLOAT_EQ(blend(BlendMode::kMultiply, 0.5f, 0.4f), 0.2f);
  EXPECT_FLOAT_EQ(blend(BlendMode::kScreen, 0.5f, 0.4f), 0.7f);
  EXPECT_FLOAT_EQ(blend(BlendMode::kOverlay, 0.25f, 0.5f), 0.25f);  // 2ab
  EXPECT_FLOAT_EQ(blend(BlendMode::kOverlay, 0.75f, 0.5f), 0.75f);  // 1 - 2(1-a)(1-b)
  EXPECT_FLOAT_EQ(blend(BlendMode::kOverlay, 0.75f, 1.0f), 1.0f);
}

TEST(Composite, LevelsMapInputRangeAndGamma) {
  Filters f;
  f.in_black = 0.2f;
  f.in_white = 0.6f;
  EXPECT_FLOAT_EQ(apply_levels(0.4f, f), 0.5f);
  EXPECT_FLOAT_EQ(apply_levels(0.1f, f), 0.0f);
  EXPECT_FLOAT_EQ(apply_levels(0.9f, f), 1.0f);
  f.gamma = 2.0f;
  EXPECT_NEAR(apply_levels(0.3f, f), std::sqrt(0.25f), 1e-6f);
  f = Filters{};
  f.out_black = 0.5f;
  EXPECT_FLOAT_EQ(apply_levels(0.5f, f), 0.75f);
}

TEST(Composite, GradientInterpolatesBetweenStops) {
  const std::vector<GradientStop> g = {{0.0f, {0, 0, 0}}, {0.5f, {1, 0, 0}}, {1.0f, {1, 1, 1}}};
  const Color a = sample_gradient(g, 0.25f);
  EXPECT_FLOAT_EQ(a.r, 0.5f);
  EXPECT_FLOAT_EQ(a.g, 0.0f);
  const Color b = sample_gradient(g, 0.75f);
  EXPECT_FLOAT_EQ(b.r, 1.0f);
  EXPECT_FLOAT_EQ(b.g, 0.5f);
  EXPECT_EQ(sample_gradient(g, -1.0f), (Color{0, 0, 0}));
  EXPECT_EQ(sample_gradient(g, 2.0f), (Color{1, 1, 1}));
}

TEST(Composite, HueRotationAndDesaturation) {
  const Color green = hue_saturation({1, 0, 0}, 120.0f, 1.0f);
  EXPECT_NEAR(green.r, 0.0f, 1e-5f);
  EXPECT_NEAR(green.g, 1.0f, 1e-5f);
  EXPECT_NEAR(green.b, 0.0f, 1e-5f);
  const Color grey = hue_saturation({0.8f, 0.4f, 0.2f}, 0.0f, 0.0f);
  EXPECT_FLOAT_EQ(grey.r, 0.8f);
  EXPECT_FLOAT_EQ(grey.g, 0.8f);
  EXPECT_FLOAT_EQ(grey.b, 0.8f);
}

TEST(Composite, TouchIsRec709Luma) {
  const Image<float> rgb = constant(2, 2, {1.0f, 0.0f, 0.0f});
  EXPECT_NEAR(touch(rgb.cview())(1, 1), 0.2126f, 1e-6f);
  EXPECT_FLOAT_EQ(touch(rgb.cview(), 0)(0, 0), 1.0f);
}

TEST(Composite, FlatColourTimesValueWithMaskAlpha) {
  const Image<float> value = constant(3, 2, {0.5f, 0.8f});  // value, mask coverage
  LayerInput layer{"base", value.cview(), {}, {}};
  layer.look.flat = {1.0f, 0.5f, 0.0f};
  layer.look.filters.opacity = 0.5f;
  const Image<float> c = color_layer(layer, 3, 2);
  EXPECT_FLOAT_EQ(c(2, 1, 0), 0.5f);
  EXPECT_FLOAT_EQ(c(2, 1, 1), 0.25f);
  EXPECT_FLOAT_EQ(c(2, 1, 2), 0.0f);
  EXPECT_FLOAT_EQ(c(2, 1, 3), 0.4f);
}

TEST(Composite, AlbedoIsSrgbEncodedThenShadedByValue) {
  const Image<float> value = constant(1, 1, {0.5f});
  const Image<float> albedo = constant(1, 1, {0.214041f, 1.0f, 0.0f});  // sRGB 0.5, 1, 0
  LayerInput layer{"base", value.cview(), albedo.cview(), {}};
  layer.look.source = ColorSource::kAlbedo;
  const Image<float> c = color_layer(layer, 1, 1);
  EXPECT_NEAR(c(0, 0, 0), 0.25f, 1e-4f);
  EXPECT_NEAR(c(0, 0, 1), 0.5f, 1e-6f);
  EXPECT_NEAR(c(0, 0, 2), 0.0f, 1e-6f);
}

TEST(Composite, AlbedoWithoutPassIsAnErrorNamingTheLayer) {
  const Image<float> value = constant(1, 1, {0.5f});
  LayerInput layer{"base", value.cview(), {}, {}};
  layer.look.source = ColorSource::kAlbedo;
  try {
    color_layer(layer, 1, 1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "layers.base.color");
  }
}

TEST(Composite, InverseValueAlphaInksDarkTouches) {
  const Image<float> value = constant(1, 1, {0.25f});
  LayerInput layer{"outline", value.cview(), {}, {}};
  layer.look.flat = {0, 0, 0};
  layer.look.alpha_from = AlphaFrom::kInverseValue;
  EXPECT_FLOAT_EQ(color_layer(layer, 1, 1)(0, 0, 3), 0.75f);
  layer.look.alpha_from = AlphaFrom::kValue;
  EXPECT_FLOAT_EQ(color_layer(layer, 1, 1)(0, 0, 3), 0.25f);
}

TEST(Composite, PaperTilesWithWrapAround) {
  Image<float> tex(2, 1, 3);
  for (int c = 0; c < 3; ++c) tex(0, 0, c) = 0.2f, tex(1, 0, c) = 0.6f;
  Paper p;
  p.texture = tex.cview();
  const Image<float> out = paper_image(p, 5, 2);
  EXPECT_FLOAT_EQ(out(0, 0, 0), 0.2f);
  EXPECT_FLOAT_EQ(out(1, 0, 0), 0.6f);
  EXPECT_FLOAT_EQ(out(2, 1, 0), 0.2f);
  EXPECT_FLOAT_EQ(out(3, 0, 1), 0.6f);
  p.color = {0.5f, 1.0f, 1.0f};
  EXPECT_FLOAT_EQ(paper_image(p, 5, 2)(1, 0, 0), 0.3f);
}

TEST(Composite, LayerOrderAndBlendModes) {
  const int w = 2, h = 1;
  Paper paper;
  paper.color = {0.5f, 0.5f, 0.5f};
  const Image<float> one = constant(w, h, {1.0f});
  LayerInput red{"red", one.cview(), {}, {}};
  red.look.flat = {1.0f, 0.0f, 0.0f};
  LayerInput half{"half", one.cview(), {}, {}};
  half.look.flat = {0.5f, 0.5f, 0.5f};
  half.look.blend = BlendMode::kMultiply;
  // red over paper, then multiply by 0.5
  Image<float> a = composite({red, half}, paper, w, h);
  EXPECT_FLOAT_EQ(a(0, 0, 0), 0.5f);
  EXPECT_FLOAT_EQ(a(0, 0, 1), 0.0f);
  EXPECT_FLOAT_EQ(a(0, 0, 3), 1.0f);
  // the other order: paper x 0.5 = 0.25, then red covers it
  Image<float> b = composite({half, red}, paper, w, h);
  EXPECT_FLOAT_EQ(b(1, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(b(1, 0, 1), 0.0f);
  // screen at half opacity over the paper: 0.5 + 0.5 * (0.75 - 0.5)
  half.look.blend = BlendMode::kScreen;
  half.look.filters.opacity = 0.5f;
  Image<float> c = composite({half}, paper, w, h);
  EXPECT_FLOAT_EQ(c(0, 0, 2), 0.625f);
}

// With a working space, only the covered pixels of a layer are converted, and a paper made
// ahead is used as it is: the same bits as converting every pixel of the paper and the layers.
TEST(Composite, WorkingSpaceConvertsCoveredPixelsOnly) {
  const int w = 37, h = 23;
  Image<float> value(w, h, 2);  // value + mask, a quarter of it uncovered
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      value(x, y, 0) = float((x * 7 + y * 3) % 11) / 10.0f;
      value(x, y, 1) = (x + y) % 4 == 0 ? 0.0f : float((x + 2 * y) % 5) / 4.0f;
    }
  std::vector<LayerInput> layers(2, LayerInput{"a", value.cview(), {}, {}});
  layers[0].look.flat = {0.9f, 0.4f, 0.2f};
  layers[1].name = "b";
  layers[1].look.flat = {0.1f, 0.3f, 0.7f};
  layers[1].look.blend = BlendMode::kOverlay;
  Paper paper;
  paper.color = {0.8f, 0.7f, 0.6f};
  std::atomic<int64_t> converted{0};  // the conversion runs on several threads
  const ToWorkingSpace square = [&](ImageView<float> rgb) {
    for (int y = 0; y < rgb.height; ++y)
      for (int x = 0; x < rgb.width; ++x)
        for (int c = 0; c < 3; ++c) rgb(x, y, c) = rgb(x, y, c) * rgb(x, y, c) + 0.01f;
    converted += int64_t(rgb.width) * rgb.height;
  };
  const Image<float> got = composite(layers, paper, w, h, square);
  EXPECT_LT(converted.load(), int64_t(w) * h * 3);
  // Every pixel converted, blended as composite() blends.
  Image<float> want = paper_image(paper, w, h);
  square(want.view());
  for (const LayerInput& layer : layers) {
    Image<float> rgba = color_layer(layer, w, h);
    square(rgba.view());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int c = 0; c < 3; ++c) {
          float& d = want(x, y, c);
          d = d + rgba(x, y, 3) * (blend(layer.look.blend, d, rgba(x, y, c)) - d);
        }
  }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(got(x, y, c), want(x, y, c)) << x << " " << y;
  // The paper made ahead is not made again.
  Image<float> made = paper_image(paper, w, h);
  square(made.view());
  paper.made = made.cview();
  converted = 0;
  const Image<float> again = composite(layers, paper, w, h, square);
  EXPECT_LT(converted.load(), int64_t(w) * h * 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(again(x, y, c), want(x, y, c)) << x << " " << y;
}

TEST(Composite, MismatchedLayerSizeIsAnError) {
  const Image<float> v = constant(2, 2, {1.0f});
  LayerInput layer{"shadow", v.cview(), {}, {}};
  EXPECT_THROW(composite({layer}, Paper{}, 3, 2), Error);
}

}  // namespace
}  // namespace emaki::composite

namespace emaki::composite {
namespace {
TEST(Composite, ColourLayerBringsItsOwnColours) {
  const Image<float> value = constant(1, 1, {0.2f, 0.4f, 0.6f, 0.5f});  // RGB + mask
  LayerInput layer{"paint", value.cview(), {}, {}, 3};
  layer.look.flat = {0, 0, 0};  // ignored
  const Image<float> c = color_layer(layer, 1, 1);
  EXPECT_FLOAT_EQ(c(0, 0, 0), 0.2f);
  EXPECT_FLOAT_EQ(c(0, 0, 2), 0.6f);
  EXPECT_FLOAT_EQ(c(0, 0, 3), 0.5f);
}
}  // namespace
}  // namespace emaki::composite
