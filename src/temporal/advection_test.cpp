#include "temporal/advection.h"

#include <gtest/gtest.h>

#include <cmath>

namespace emaki::temporal {
namespace {

// A guide whose every pixel is distinct: its normalised coordinates shifted by `dx` pixels.
Image<float> position_guide(int w, int h, float dx) {
  Image<float> g(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      g(x, y, 0) = (x + dx) / w;
      g(x, y, 1) = float(y) / h;
      g(x, y, 2) = 0.5f;
    }
  return g;
}

Image<float> stripes(int w, int h, float dx) {
  Image<float> s(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) s(x, y) = 0.5f + 0.5f * std::sin(0.7f * (x + dx) + 0.3f * y);
  return s;
}

double mean_abs_diff(const Image<float>& a, const Image<float>& b, int margin) {
  double s = 0;
  int n = 0;
  for (int y = margin; y < a.height() - margin; ++y)
    for (int x = margin; x < a.width() - margin; ++x) s += std::abs(a(x, y) - b(x, y)), ++n;
  return s / n;
}

// The surface moved 4 pixels to the left between t-1 and t: the advected frame is the previous
// stylized frame moved with it, and much closer to that than to the unmoved previous frame.
TEST(Advection, CarriesThePreviousFrameAlongThePositionGuide) {
  const int w = 64, h = 48;
  const Image<float> prev = stripes(w, h, 0.0f);
  const Image<float> g_prev = position_guide(w, h, 0.0f), g_cur = position_guide(w, h, 4.0f);
  AdvectionInputs in;
  in.previous_stylized = prev.cview();
  in.previous_guide = g_prev.cview();
  in.current_guide = g_cur.cview();
  synth::Params p;
  p.patch_size = 5;
  const Image<float> adv = advect(in, p).value;
  ASSERT_EQ(adv.channels(), 1);
  const Image<float> expected = stripes(w, h, 4.0f);
  const double moved = mean_abs_diff(adv, expected, 6);
  const double unmoved = mean_abs_diff(adv, prev, 6);
  EXPECT_LT(moved, 0.06);
  EXPECT_LT(moved, 0.3 * unmoved);
}

// A larger motion than the default radius covers at this size is found with a radius that does.
TEST(Advection, FindsMotionWithinTheSearchRadius) {
  const int w = 96, h = 64;
  const Image<float> prev = stripes(w, h, 0.0f);
  const Image<float> g_prev = position_guide(w, h, 0.0f), g_cur = position_guide(w, h, 12.0f);
  AdvectionInputs in;
  in.previous_stylized = prev.cview();
  in.previous_guide = g_prev.cview();
  in.current_guide = g_cur.cview();
  in.search_radius = 16;
  const Image<float> adv = advect(in, synth::Params{}).value;
  const Image<float> expected = stripes(w, h, 12.0f);
  // Where the moved content exists in the previous frame (x + 12 < w), it is carried exactly.
  double s = 0;
  int n = 0;
  for (int y = 6; y < h - 6; ++y)
    for (int x = 6; x < w - 12 - 6; ++x) s += std::abs(adv(x, y) - expected(x, y)), ++n;
  EXPECT_LT(s / n, 0.03);
}

// With the surfaces' motion vectors the field starts where they point: a motion five times the
// search radius is found at once, where a start at the identity could not reach it.
TEST(Advection, StartsWhereTheMotionVectorsPoint) {
  const int w = 128, h = 64, shift = 40;
  const Image<float> g_prev = position_guide(w, h, 0.0f), g_cur = position_guide(w, h, shift);
  Image<float> rest_prev(w, h, 4), rest_cur(w, h, 4), motion(w, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c)
        rest_prev(x, y, c) = g_prev(x, y, c), rest_cur(x, y, c) = g_cur(x, y, c);
      rest_prev(x, y, 3) = rest_cur(x, y, 3) = 1.0f;  // one object
      motion(x, y, 0) = float(shift);
    }
  motion(0, 0, 0) = NAN;  // a damaged vector (outside the pixels counted) must not break the field
  const Image<float> prev = stripes(w, h, 0.0f);
  AdvectionInputs in;
  in.previous_stylized = prev.cview();
  in.previous_guide = g_prev.cview();
  in.current_guide = g_cur.cview();
  in.surfaces = Surfaces{rest_prev.cview(), rest_cur.cview(), motion.cview()};
  synth::Params p;
  p.patch_size = 5;
  const AdvectionField f = advection_field(in, p);
  int found = 0, n = 0;
  for (int y = 2; y < h - 2; ++y)
    for (int x = 2; x + shift < w - 2; ++x, ++n)
      found += f.nnf(x, y, 0) == x + shift && f.nnf(x, y, 1) == y;
  EXPECT_GT(found, 0.99 * n) << found << " of " << n;
}

// Outside its mask the previous frame had nothing; the advection reads the empty value there.
TEST(Advection, MaskedPreviousFrameUsesTheEmptyValue) {
  const int w = 48, h = 32;
  Image<float> prev(w, h, 2);  // value 0.2 everywhere, coverage 0: nothing was synthesized
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) prev(x, y, 0) = 0.2f;
  const Image<float> g = position_guide(w, h, 0.0f);
  AdvectionInputs in;
  in.previous_stylized = prev.cview();
  in.previous_guide = g.cview();
  in.current_guide = g.cview();
  in.empty_value = 0.9f;
  const Image<float> adv = advect(in, synth::Params{}).value;
  EXPECT_NEAR(adv(w / 2, h / 2), 0.9f, 1e-4f);
}

// One field serves every layer of a frame: it depends on neither the layer's value nor its mask,
// so a masked layer carried along a shared field gets exactly what advecting it alone gives, and
// the same field carries another layer's value too.
TEST(Advection, OneFieldServesLayersWithOtherValuesAndMasks) {
  const int w = 64, h = 48;
  const Image<float> a = stripes(w, h, 0.0f), b = stripes(w, h, 2.5f);
  const Image<float> g_prev = position_guide(w, h, 0.0f), g_cur = position_guide(w, h, 3.0f);
  Image<float> mask(w, h, 1);
  for (int y = 10; y < 30; ++y)
    for (int x = 20; x < 50; ++x) mask(x, y) = 1.0f;
  AdvectionInputs in;
  in.previous_guide = g_prev.cview();
  in.current_guide = g_cur.cview();
  synth::Params p;
  p.patch_size = 5;
  in.previous_stylized = a.cview();
  const AdvectionField field = advection_field(in, p);
  for (const Image<float>* value : {&a, &b})
    for (const bool masked : {false, true}) {
      in.previous_stylized = value->cview();
      in.current_mask.reset();
      if (masked) in.current_mask = mask.cview();
      const Image<float> alone = advect(in, p).value, shared = advect(in, p, &field).value;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) ASSERT_EQ(alone(x, y), shared(x, y)) << x << "," << y;
      if (masked) {
        EXPECT_EQ(shared(0, 0), in.empty_value);  // outside the mask
      }
    }
}

}  // namespace
}  // namespace emaki::temporal
