// Per-pixel guide weights: a map of ones changes nothing, a map of zeros drops the guide, a
// constant map acts as the weight, the map decides where its guide counts, and results stay the
// same for any thread count and either distance kernel. The uniformity map likewise.
#include "synth/weight_maps.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "core/performance.h"
#include "synth/patch_distance.h"
#include "synth/synthesizer.h"
#include "synth/test_images.h"

namespace emaki::synth {
namespace {

using namespace test;

// Two guides: `a` (weight 0.5, the one that gets maps) and `b` (weight 1, the heaviest, so that
// dropping `a` leaves every other channel's quantisation as it was).
struct TwoGuides {
  Image<float> style = noise(72, 56, 1, 21);
  Image<float> a_src = textured(72, 56, 22), a_tgt = textured(80, 60, 23);
  Image<float> b_src = textured(72, 56, 24), b_tgt = textured(80, 60, 25);
  Inputs inputs(float a_weight = 0.5f) const {
    Inputs in;
    in.style = style.cview();
    in.guides.push_back({"a", a_src.cview(), a_tgt.cview(), a_weight});
    in.guides.push_back({"b", b_src.cview(), b_tgt.cview(), 1.0f});
    return in;
  }
};

Image<float> constant(int w, int h, float v) {
  Image<float> m(w, h, 1);
  m.fill(v);
  return m;
}

Result run(const Inputs& in) {
  OutputRequest req;
  req.nnf = true;
  req.error = true;
  return synthesize(in, Params(), req);
}

bool same_nnf(const Image<int32_t>& a, const Image<int32_t>& b) {
  for (int y = 0; y < a.height(); ++y)
    if (std::memcmp(a.row(y), b.row(y), sizeof(int32_t) * 2 * a.width()) != 0) return false;
  return true;
}

double mean_abs_diff(const Image<float>& a, const Image<float>& b) {
  double s = 0.0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) s += std::abs(a(x, y) - b(x, y));
  return s / (double(a.width()) * a.height());
}

TEST(WeightMaps, MapOfOnesIsBitIdenticalToNoMap) {
  const TwoGuides t;
  const Image<float> ones = constant(80, 60, 1.0f);
  Inputs mapped = t.inputs();
  mapped.guides[0].weight_map = Plane(ones.cview());
  const Result with = run(mapped), without = run(t.inputs());
  EXPECT_TRUE(same_bits(with.image, without.image));
  EXPECT_TRUE(same_bits(with.error, without.error));
  EXPECT_TRUE(same_nnf(with.nnf, without.nnf));
}

TEST(WeightMaps, MapOfZerosEqualsDroppingTheGuide) {
  const TwoGuides t;
  const Image<float> zeros = constant(80, 60, 0.0f);
  Inputs mapped = t.inputs();
  mapped.guides[0].weight_map = Plane(zeros.cview());
  Inputs dropped = t.inputs();
  dropped.guides.erase(dropped.guides.begin());
  const Result with = run(mapped), without = run(dropped);
  EXPECT_TRUE(same_bits(with.image, without.image));
  EXPECT_TRUE(same_bits(with.error, without.error));
  EXPECT_TRUE(same_nnf(with.nnf, without.nnf));
  EXPECT_FALSE(same_bits(with.image, run(t.inputs()).image));  // the guide did count
}

// A pair of weight 0 changes nothing, whatever its map: its channels quantise to 0 on both sides
// and the other channels' weights stay as they were (the pipeline leaves a temporal pair of
// weight 0 out on this ground).
TEST(WeightMaps, PairOfWeightZeroEqualsDroppingIt) {
  const TwoGuides t;
  const Image<float> map = noise(80, 60, 1, 26);
  Inputs zero = t.inputs(0.0f);
  zero.guides[0].weight_map = Plane(map.cview());
  Inputs dropped = t.inputs();
  dropped.guides.erase(dropped.guides.begin());
  const Result with = run(zero), without = run(dropped);
  EXPECT_TRUE(same_bits(with.image, without.image));
  EXPECT_TRUE(same_bits(with.error, without.error));
  EXPECT_TRUE(same_nnf(with.nnf, without.nnf));
}

// A constant map c on weight w acts as the weight c x w. Not bit for bit: the guide's channels
// are quantised for w either way, and c multiplies their sum.
TEST(WeightMaps, ConstantMapActsAsTheWeight) {
  const TwoGuides t;
  const Image<float> quarter = constant(80, 60, 0.25f);
  Inputs mapped = t.inputs(2.0f);
  mapped.guides[0].weight_map = Plane(quarter.cview());
  const Image<float> with = run(mapped).image;
  const Image<float> as_weight = run(t.inputs(0.5f)).image;
  const Image<float> unmapped = run(t.inputs(2.0f)).image;
  const double d_weight = mean_abs_diff(with, as_weight),
               d_unmapped = mean_abs_diff(with, unmapped);
  EXPECT_LT(d_weight, 0.25 * d_unmapped) << d_weight << " vs " << d_unmapped;
}

// Guide `shift` says the target is the source moved 6 pixels right; guide `still` says it is the
// source as it is. Where shift's map is 1 its match wins (it weighs more); where it is 0, still's.
TEST(WeightMaps, MapDecidesWhereItsGuideCounts) {
  const int w = 96, h = 64, shift = 6;
  const Image<float> style = noise(w, h, 1, 31);
  const Image<float> still = textured(w, h, 32);
  const Image<float> moving = textured(w, h, 33);
  Image<float> moved(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) moved(x, y, c) = moving(std::min(w - 1, x + shift), y, c);
  Image<float> left(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x) left(x, y) = 1.0f;
  Inputs in;
  in.style = style.cview();
  in.guides.push_back({"still", still.cview(), still.cview(), 1.0f});
  in.guides.push_back({"shift", moving.cview(), moved.cview(), 4.0f});
  in.guides[1].weight_map = Plane(left.cview());
  Params params;
  params.uniformity = 0.0f;
  params.style_weight = 0.0f;  // the guides alone decide
  OutputRequest req;
  req.nnf = true;
  const Result res = synthesize(in, params, req);
  int shifted_left = 0, still_right = 0, left_n = 0, right_n = 0;
  for (int y = 8; y < h - 8; ++y)
    for (int x = 8; x < w - 8 - shift; ++x) {
      if (std::abs(x - w / 2) < 4) continue;  // patches straddling the map's edge
      const bool is_shift = res.nnf(x, y, 0) == x + shift && res.nnf(x, y, 1) == y;
      const bool is_still = res.nnf(x, y, 0) == x && res.nnf(x, y, 1) == y;
      if (x < w / 2)
        ++left_n, shifted_left += is_shift;
      else
        ++right_n, still_right += is_still;
    }
  EXPECT_GT(double(shifted_left) / left_n, 0.95);
  EXPECT_GT(double(still_right) / right_n, 0.95);
}

// A map with every kind of value: any thread count and either kernel give the same bits.
TEST(WeightMaps, BitIdenticalForAnyThreadCountAndKernel) {
  const TwoGuides t;
  const Image<float> map = noise(80, 60, 1, 40);
  Inputs in = t.inputs();
  in.guides[1].weight_map = Plane(map.cview());
  std::vector<Result> results;
  for (int threads : {1, 2, 3}) {
    const ScopedThreadCount count(threads);
    results.push_back(run(in));
  }
  Performance scalar = performance();
  scalar.simd = false;  // as EMAKI_SIMD=scalar sets it at a front end
  set_performance(scalar);
  results.push_back(run(in));
  scalar.simd = true;
  set_performance(scalar);
  for (std::size_t i = 1; i < results.size(); ++i) {
    EXPECT_TRUE(same_bits(results[0].image, results[i].image)) << "run " << i;
    EXPECT_TRUE(same_nnf(results[0].nnf, results[i].nnf)) << "run " << i;
  }
}

std::string error_subject(const Inputs& in) {
  try {
    validate(in, Params());
  } catch (const Error& e) {
    return std::string(e.subject()) + ": " + e.what();
  }
  return "";
}

TEST(WeightMaps, ValidateNamesTheMap) {
  const TwoGuides t;
  Inputs in = t.inputs();
  const Image<float> small = constant(79, 60, 1.0f);
  in.guides[0].weight_map = Plane(small.cview());
  in.guides[0].weight_map_name = "paint.png";
  EXPECT_EQ(error_subject(in).rfind("paint.png", 0), 0u) << error_subject(in);
  Image<float> bad = constant(80, 60, 0.5f);
  bad(3, 2) = 1.5f;
  in.guides[0].weight_map = Plane(bad.cview());
  EXPECT_NE(error_subject(in).find("(3, 2)"), std::string::npos) << error_subject(in);
  bad(3, 2) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error_subject(in).find("(3, 2)"), std::string::npos) << error_subject(in);
  in.guides[0].weight_map_name.clear();
  EXPECT_EQ(error_subject(in).rfind("a", 0), 0u) << error_subject(in);
  const Image<float> ok = constant(80, 60, 0.5f);
  in = t.inputs();
  for (int k = 0; k <= kMaxWeightMaps; ++k) {
    in.guides.push_back({"more", t.a_src.cview(), t.a_tgt.cview(), 1.0f});
    in.guides.back().weight_map = Plane(ok.cview());
  }
  EXPECT_EQ(error_subject(in).rfind("guides", 0), 0u) << error_subject(in);
}

// Params::uniformity_map: ones change nothing, zeros switch the term off, any map gives the same
// bits for any thread count, and a bad map is named.
Result run_with(const Inputs& in, float uniformity, const Image<float>* map) {
  Params p;
  p.uniformity = uniformity;
  if (map) p.uniformity_map = Plane(map->cview());
  OutputRequest req;
  req.nnf = true;
  return synthesize(in, p, req);
}

TEST(UniformityMap, OnesAreNoMapAndZerosNoTerm) {
  const TwoGuides t;
  const Image<float> ones = constant(80, 60, 1.0f), zeros = constant(80, 60, 0.0f);
  const Result plain = run_with(t.inputs(), 3500.0f, nullptr);
  const Result with_ones = run_with(t.inputs(), 3500.0f, &ones);
  EXPECT_TRUE(same_bits(plain.image, with_ones.image));
  EXPECT_TRUE(same_nnf(plain.nnf, with_ones.nnf));
  const Result off = run_with(t.inputs(), 0.0f, nullptr);
  const Result with_zeros = run_with(t.inputs(), 3500.0f, &zeros);
  EXPECT_TRUE(same_bits(off.image, with_zeros.image));
  EXPECT_TRUE(same_nnf(off.nnf, with_zeros.nnf));
  EXPECT_FALSE(same_nnf(plain.nnf, off.nnf));  // the term did count
}

TEST(UniformityMap, BitIdenticalForAnyThreadCount) {
  const TwoGuides t;
  const Image<float> map = noise(80, 60, 1, 41);
  std::vector<Result> results;
  for (int threads : {1, 2, 3}) {
    const ScopedThreadCount count(threads);
    results.push_back(run_with(t.inputs(), 3500.0f, &map));
  }
  for (std::size_t i = 1; i < results.size(); ++i) {
    EXPECT_TRUE(same_bits(results[0].image, results[i].image)) << "run " << i;
    EXPECT_TRUE(same_nnf(results[0].nnf, results[i].nnf)) << "run " << i;
  }
  EXPECT_FALSE(same_nnf(results[0].nnf, run_with(t.inputs(), 3500.0f, nullptr).nnf));
}

TEST(UniformityMap, ValidateNamesIt) {
  const TwoGuides t;
  Params p;
  Image<float> bad = constant(80, 60, 0.5f);
  bad(4, 5) = -0.5f;
  p.uniformity_map = Plane(bad.cview());
  try {
    validate(t.inputs(), p);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.subject()), "uniformity map");
    EXPECT_NE(std::string(e.what()).find("(4, 5)"), std::string::npos) << e.what();
  }
  const Image<float> small = constant(80, 59, 1.0f);
  p.uniformity_map = Plane(small.cview());
  EXPECT_THROW(validate(t.inputs(), p), Error);
}

}  // namespace
}  // namespace emaki::synth
