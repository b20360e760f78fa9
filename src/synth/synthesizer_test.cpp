// Whole synthesis on small synthetic images: identity, schedule, determinism, masks, precision,
// validation.
#include "synth/synthesizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "synth/patch_match.h"
#include "synth/test_images.h"

namespace emaki::synth {
namespace {

using namespace test;

struct Fixture {
  Image<float> style, guide_src, guide_tgt;
  Inputs inputs() const {
    Inputs in;
    in.style = style.cview();
    in.guides.push_back({"guide", guide_src.cview(), guide_tgt.cview(), -1.0f});
    return in;
  }
};

TEST(Synthesize, IdentityReproducesExemplarWithZeroError) {
  Fixture f;
  f.style = textured(64, 48, 1);
  f.guide_src = textured(64, 48, 2);
  f.guide_tgt = f.guide_src.clone();
  Params params;
  params.seed = 5;
  // EbSynth's iteration counts: emaki's leaner default schedule leaves a few pixels of this
  // tiny, 3-level image one search short of the exact answer.
  params.search_vote_iters = 6;
  params.patch_match_iters = 4;
  OutputRequest req;
  req.error = true;
  req.nnf = true;
  const Result res = synthesize(f.inputs(), params, req);
  // Away from the border: target pixels within r of the edge all map to the source's edge
  // patches (clamped), which crowds their occupancy and pushes neighbours up to 2r further in
  // to other, equally perfect-looking but not identical, matches.
  const int b = 2 * params.patch_size;
  int wrong = 0;
  for (int y = b; y < 48 - b; ++y)
    for (int x = b; x < 64 - b; ++x) {
      wrong += res.nnf(x, y, 0) != x || res.nnf(x, y, 1) != y || res.error(x, y) != 0.0f;
      for (int c = 0; c < 3; ++c) wrong += std::abs(res.image(x, y, c) - f.style(x, y, c)) > 1e-6f;
    }
  EXPECT_EQ(wrong, 0);
}

// The finest level's search-vote count can be lowered alone (temporal frames use 1).
TEST(Schedule, FinestSearchVoteItersOverridesOnlyTheFinestLevel) {
  Params p;
  const std::vector<LevelSchedule> base = make_schedule(p, 6);
  p.finest_search_vote_iters = 1;
  const std::vector<LevelSchedule> lean = make_schedule(p, 6);
  ASSERT_EQ(base.size(), 6u);
  ASSERT_EQ(lean.size(), 6u);
  EXPECT_EQ(base.back().search_vote_iters, 2);
  EXPECT_EQ(lean.back().search_vote_iters, 1);
  for (std::size_t l = 0; l + 1 < base.size(); ++l) {
    EXPECT_EQ(lean[l].search_vote_iters, base[l].search_vote_iters) << l;
    EXPECT_EQ(lean[l].patch_match_iters, base[l].patch_match_iters) << l;
    EXPECT_EQ(lean[l].max_search_radius, base[l].max_search_radius) << l;
  }
}

// The identity start, one level, no search: the field is the identity, clamped to the source's
// patch centres, and scaled when the target is larger.
TEST(Synthesize, IdentityFieldInit) {
  Fixture f;
  f.style = noise(40, 30, 1, 4);
  f.guide_src = textured(40, 30, 5);
  f.guide_tgt = textured(80, 60, 6);
  Params params;
  params.init = FieldInit::kIdentity;
  params.pyramid_levels = 1;
  params.search_vote_iters = 0;
  OutputRequest req;
  req.nnf = true;
  const Result res = synthesize(f.inputs(), params, req);
  const int r = params.patch_size / 2;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      ASSERT_EQ(res.nnf(x, y, 0), std::clamp(x / 2, r, 39 - r)) << x << "," << y;
      ASSERT_EQ(res.nnf(x, y, 1), std::clamp(y / 2, r, 29 - r)) << x << "," << y;
    }
  // With search, a random start would have to find the same field; the identity start keeps it.
  params.search_vote_iters = 1;
  params.patch_match_iters = 1;
  params.search_radius = 2;
  f.guide_tgt = f.guide_src.clone();
  const Result same = synthesize(f.inputs(), params, req);
  int moved = 0;
  for (int y = 2 * r; y < 30 - 2 * r; ++y)
    for (int x = 2 * r; x < 40 - 2 * r; ++x)
      moved += same.nnf(x, y, 0) != x || same.nnf(x, y, 1) != y;
  EXPECT_EQ(moved, 0);
}

TEST(Synthesize, BitIdenticalForAnyThreadCountAndRun) {
  Fixture f;
  f.style = noise(96, 80, 3, 4);
  f.guide_src = textured(96, 80, 5);
  f.guide_tgt = textured(120, 72, 6);
  Params params;
  OutputRequest req;
  req.nnf = true;
  std::vector<Result> results;
  for (int threads : {1, 2, 3, 2}) {
    const ScopedThreadCount count(threads);
    results.push_back(synthesize(f.inputs(), params, req));
  }
  for (std::size_t i = 1; i < results.size(); ++i) {
    EXPECT_TRUE(same_bits(results[0].image, results[i].image)) << "run " << i;
    for (int y = 0; y < 72; ++y)
      ASSERT_EQ(0, std::memcmp(results[0].nnf.row(y), results[i].nnf.row(y), 120 * 2 * 4));
  }
}

// A warm start runs the finest level alone from the given field: a converged field given back,
// with no search, gives back its image; entries whose patch leaves the source (a mask's (-1, -1),
// values from a hostile file) start at random draws; thread counts do not matter.
TEST(Synthesize, WarmStartFromAGivenField) {
  Fixture f;
  f.style = noise(64, 48, 1, 4);
  f.guide_src = textured(64, 48, 5);
  f.guide_tgt = textured(72, 40, 6);
  Params params;
  OutputRequest req;
  req.nnf = true;
  const Result cold = synthesize(f.inputs(), params, req);
  ASSERT_GT(cold.pyramid_levels, 1);

  Params warm = params;
  warm.initial_nnf = cold.nnf.cview();
  warm.finest_search_vote_iters = 0;
  Result again = synthesize(f.inputs(), warm, req);
  EXPECT_EQ(again.pyramid_levels, 1);
  for (int y = 0; y < 40; ++y)
    ASSERT_EQ(0, std::memcmp(again.nnf.row(y), cold.nnf.row(y), 72 * 2 * 4)) << y;

  Image<int32_t> hostile = cold.nnf.clone();
  const int32_t junk[][2] = {{-1, -1}, {0, 0}, {63, 47}, {1 << 30, -5}, {INT32_MIN, INT32_MAX}};
  for (int i = 0; i < 5; ++i)
    hostile(7 * i, 3 * i, 0) = junk[i][0], hostile(7 * i, 3 * i, 1) = junk[i][1];
  warm.initial_nnf = hostile.cview();
  again = synthesize(f.inputs(), warm, req);
  const int r = params.patch_size / 2;
  // Entries whose patch leaves the source start at random_nnf's draw for that pixel.
  const Image<int32_t> drawn = random_nnf(72, 40, 64, 48, r, warm.seed);
  for (int i = 0; i < 5; ++i) {
    const int x = again.nnf(7 * i, 3 * i, 0), y = again.nnf(7 * i, 3 * i, 1);
    EXPECT_TRUE(x >= r && x < 64 - r && y >= r && y < 48 - r) << i << ": " << x << ", " << y;
    EXPECT_EQ(x, drawn(7 * i, 3 * i, 0)) << i;
    EXPECT_EQ(y, drawn(7 * i, 3 * i, 1)) << i;
  }

  warm.finest_search_vote_iters = 1;
  std::vector<Result> results;
  for (int threads : {1, 2, 3}) {
    const ScopedThreadCount count(threads);
    results.push_back(synthesize(f.inputs(), warm, req));
  }
  for (std::size_t i = 1; i < results.size(); ++i)
    EXPECT_TRUE(same_bits(results[0].image, results[i].image)) << "run " << i;

  Image<int32_t> small(71, 40, 2);
  warm.initial_nnf = small.cview();
  try {
    synthesize(f.inputs(), warm);
    ADD_FAILURE() << "a field of the wrong size was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("initial_nnf"), std::string::npos) << e.what();
  }
}

// With no search the output is the warm start's first estimate: the vote of the given field,
// each pixel's own match's centre value (warm_sharp_estimate 1), or the mix between.
TEST(Synthesize, WarmSharpEstimateTakesEachPixelsOwnMatch) {
  Fixture f;
  f.style = noise(64, 48, 1, 4);
  f.guide_src = textured(64, 48, 5);
  f.guide_tgt = textured(72, 40, 6);
  OutputRequest req;
  req.nnf = true;
  const Result cold = synthesize(f.inputs(), Params{}, req);
  Params warm;
  warm.initial_nnf = cold.nnf.cview();
  warm.finest_search_vote_iters = 0;
  const Result voted = synthesize(f.inputs(), warm, req);
  warm.warm_sharp_estimate = 1.0f;
  const Result sharp = synthesize(f.inputs(), warm, req);
  warm.warm_sharp_estimate = 0.25f;
  const Result mixed = synthesize(f.inputs(), warm, req);
  int differ = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 72; ++x) {
      const float own = f.style(cold.nnf(x, y, 0), cold.nnf(x, y, 1));
      ASSERT_EQ(sharp.image(x, y), own) << x << ", " << y;
      const float v = voted.image(x, y);
      EXPECT_NEAR(mixed.image(x, y), v + 0.25f * (own - v), 1e-5f) << x << ", " << y;
      differ += v != own;
    }
  EXPECT_GT(differ, 72 * 40 / 2);  // the vote blurs what the centres keep

  Params cold_params;
  cold_params.warm_sharp_estimate = 1.0f;  // no warm start: nothing changes
  EXPECT_TRUE(same_bits(synthesize(f.inputs(), cold_params).image, cold.image));
  for (float bad : {-0.5f, 1.5f, std::numeric_limits<float>::quiet_NaN()}) {
    warm.warm_sharp_estimate = bad;
    try {
      synthesize(f.inputs(), warm);
      ADD_FAILURE() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), "warm_sharp_estimate");
    }
  }
}

TEST(Synthesize, SeedChangesTheResult) {
  Fixture f;
  f.style = noise(64, 48, 1, 4);
  f.guide_src = textured(64, 48, 5);
  f.guide_tgt = textured(64, 48, 6);
  Params a, b;
  b.seed = 99;
  EXPECT_FALSE(same_bits(synthesize(f.inputs(), a).image, synthesize(f.inputs(), b).image));
}

TEST(Synthesize, MaskLeavesOutsideTransparent) {
  Fixture f;
  f.style = noise(48, 40, 1, 8);
  f.guide_src = textured(48, 40, 9);
  f.guide_tgt = textured(48, 40, 10);
  Image<float> mask(48, 40, 1);
  for (int y = 10; y < 30; ++y)
    for (int x = 12; x < 36; ++x) mask(x, y) = 1.0f;
  Inputs in = f.inputs();
  in.target_mask = Plane(mask.cview());
  OutputRequest req;
  req.nnf = true;
  const Result res = synthesize(in, Params(), req);
  ASSERT_EQ(res.image.channels(), 2);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 48; ++x) {
      const bool inside = mask(x, y) > 0.0f;
      EXPECT_EQ(res.image(x, y, 1), inside ? 1.0f : 0.0f);
      if (!inside) {
        EXPECT_EQ(res.image(x, y, 0), 0.0f);
      }
      const bool far = x < 8 || x > 39 || y < 6 || y > 33;  // beyond the dilated mask
      if (far) {
        EXPECT_EQ(res.nnf(x, y, 0), -1);
      }
    }
}

TEST(Synthesize, FloatGuidesKeepThousandthSteps) {
  // Position-like guide with 0.001 steps: the target is the source shifted by 7 pixels. With
  // 8-bit guides (1/255 steps) neighbours would tie; with emaki's quantisation the field must
  // find the exact shift.
  const int w = 160, h = 120, shift = 7;
  Image<float> src(w, h, 2), tgt(w - shift, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      src(x, y, 0) = 0.3f + 0.001f * float(x);
      src(x, y, 1) = 0.2f + 0.001f * float(y);
      if (x < w - shift) {
        tgt(x, y, 0) = 0.3f + 0.001f * float(x + shift);
        tgt(x, y, 1) = 0.2f + 0.001f * float(y);
      }
    }
  Image<float> style(w, h, 1);  // flat: only the guide decides
  Inputs in;
  in.style = style.cview();
  in.guides.push_back({"position", src.cview(), tgt.cview(), 1.0f});
  Params params;
  params.uniformity = 0.0f;
  OutputRequest req;
  req.nnf = true;
  const Result res = synthesize(in, params, req);
  int exact = 0, total = 0;
  for (int y = 4; y < h - 4; ++y)
    for (int x = 4; x < w - shift - 4; ++x) {
      ++total;
      exact += res.nnf(x, y, 0) == x + shift && res.nnf(x, y, 1) == y;
    }
  EXPECT_GT(double(exact) / total, 0.99);
}

TEST(Cancel, AHookThatNeverFiresChangesNothing) {
  Fixture f;
  f.style = noise(64, 48, 3, 4);
  f.guide_src = textured(64, 48, 5);
  f.guide_tgt = textured(72, 40, 6);
  Params plain, hooked;
  int polls = 0;
  hooked.cancel = [&polls] { return ++polls < 0; };
  EXPECT_TRUE(same_bits(synthesize(f.inputs(), plain).image, synthesize(f.inputs(), hooked).image));
  EXPECT_GT(polls, 10);  // polled at every level and sweep
}

TEST(Cancel, StopsTheRunWithCancelled) {
  Fixture f;
  f.style = noise(64, 48, 3, 4);
  f.guide_src = textured(64, 48, 5);
  f.guide_tgt = textured(72, 40, 6);
  Params params;
  int polls = 0;
  params.cancel = [&polls] { return ++polls == 5; };
  EXPECT_THROW(synthesize(f.inputs(), params), Cancelled);
  EXPECT_EQ(polls, 5);  // not polled again once it said stop
}

TEST(Synthesize, ScopedThreadCountGivesTheSameResult) {
  Fixture f;
  f.style = noise(64, 48, 3, 4);
  f.guide_src = textured(64, 48, 5);
  f.guide_tgt = textured(72, 40, 6);
  const Result all = synthesize(f.inputs(), Params());
  ScopedThreadCount one(1);
  EXPECT_EQ(thread_count(), 1);
  EXPECT_TRUE(same_bits(all.image, synthesize(f.inputs(), Params()).image));
}

TEST(Validate, RejectsBadInputsNamingThem) {
  Fixture f;
  f.style = noise(32, 32, 3, 1);
  f.guide_src = noise(32, 32, 1, 2);
  f.guide_tgt = noise(40, 30, 1, 3);
  Params p;
  p.patch_size = 4;
  EXPECT_THROW(validate(f.inputs(), p), Error);
  p.patch_size = 5;
  EXPECT_NO_THROW(validate(f.inputs(), p));
  Image<float> wrong(31, 32, 1);
  Inputs in = f.inputs();
  in.guides[0].source = wrong.cview();
  try {
    validate(in, p);
    FAIL() << "size mismatch accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "guide");
  }
  in.guides[0].source_name = "guide source";
  try {
    validate(in, p);
    FAIL() << "size mismatch accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "guide source");
  }
  p.patch_size = 4;
  try {
    validate(f.inputs(), p);
    FAIL() << "even patch size accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "patch_size");
  }
  p.patch_size = 5;
  Image<float> nan = noise(32, 32, 1, 4);
  nan(3, 4) = std::numeric_limits<float>::quiet_NaN();
  in = f.inputs();
  in.guides[0].source = nan.cview();
  EXPECT_THROW(validate(in, p), Error);
  // Infinities of either sign too, named at their pixel; the largest finite values pass.
  for (const float bad :
       {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()}) {
    Image<float> inf = noise(32, 32, 1, 4);
    inf(30, 17) = bad;
    in = f.inputs();
    in.guides[0].target = inf.cview();
    try {
      validate(in, p);
      FAIL() << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("(30, 17)"), std::string::npos) << e.what();
    }
  }
  Image<float> large = noise(32, 32, 1, 4);
  large(1, 1) = std::numeric_limits<float>::max();
  large(2, 1) = -std::numeric_limits<float>::max();
  large(3, 1) = std::numeric_limits<float>::denorm_min();
  in = f.inputs();
  in.guides[0].target = large.cview();
  EXPECT_NO_THROW(validate(in, p));
  Image<float> tiny(4, 4, 1);
  in = f.inputs();
  in.guides[0].target = tiny.cview();
  EXPECT_THROW(validate(in, p), Error);
}

}  // namespace
}  // namespace emaki::synth
