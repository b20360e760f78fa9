// Unit tests of the synthesis engine on small synthetic images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "synth/patch_distance.h"
#include "synth/patch_match.h"
#include "synth/pyramid.h"
#include "synth/synthesizer.h"
#include "synth/voting.h"

namespace emaki::synth {
namespace {

Image<float> noise(int w, int h, int c, uint64_t seed) {
  Image<float> im(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) {
        CounterRng rng(hash_key(seed, uint64_t(y) * 4096 + x, uint64_t(k)));
        im(x, y, k) = rng.uniform_float();
      }
  return im;
}

// A smooth guide plus noise: unique patches, so the identity is the only perfect match.
Image<float> textured(int w, int h, uint64_t seed) {
  Image<float> im = noise(w, h, 3, seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      im(x, y, 0) = 0.5f * im(x, y, 0) + 0.5f * float(x) / float(w);
      im(x, y, 1) = 0.5f * im(x, y, 1) + 0.5f * float(y) / float(h);
    }
  return im;
}

bool same_bits(const Image<float>& a, const Image<float>& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels())
    return false;
  for (int y = 0; y < a.height(); ++y)
    if (std::memcmp(a.row(y), b.row(y), sizeof(float) * a.width() * a.channels()) != 0)
      return false;
  return true;
}

// ---------------------------------------------------------------------------------------------
// Patch distance kernels

TEST(PatchDistance, Avx2EqualsScalar) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  CounterRng rng(7);
  for (int channels : {8, 16, 24, 32}) {
    for (int patch : {3, 5, 7, 9}) {
      const int row_elems = patch * channels;
      const std::ptrdiff_t stride = row_elems + 40;
      std::vector<int16_t> a(stride * patch), b(stride * patch);
      for (int trial = 0; trial < 50; ++trial) {
        for (auto& v : a) v = int16_t(rng.uniform(kQuantMax + 1));
        for (auto& v : b) v = int16_t(rng.uniform(kQuantMax + 1));
        if (trial == 0) std::fill(a.begin(), a.end(), int16_t(kQuantMax));  // worst case
        if (trial == 0) std::fill(b.begin(), b.end(), int16_t(0));
        const int64_t full = patch_ssd_scalar(a.data(), stride, b.data(), stride, row_elems, patch,
                                              std::numeric_limits<int64_t>::max());
        const int64_t bound = trial % 2 ? full / 3 : std::numeric_limits<int64_t>::max();
        EXPECT_EQ(patch_ssd_scalar(a.data(), stride, b.data(), stride, row_elems, patch, bound),
                  patch_ssd_avx2(a.data(), stride, b.data(), stride, row_elems, patch, bound))
            << "channels " << channels << " patch " << patch << " trial " << trial;
      }
    }
  }
}

TEST(PatchDistance, ExactForLargestDifferences) {
  // 9x9 patch, 32 channels, every difference 16383: 81 * 32 * 16383^2 overflows int32.
  const int patch = 9, channels = 32, row_elems = patch * channels;
  std::vector<int16_t> a(row_elems * patch, kQuantMax), b(row_elems * patch, 0);
  const int64_t expect = int64_t(patch) * row_elems * int64_t(kQuantMax) * kQuantMax;
  EXPECT_EQ(patch_ssd_scalar(a.data(), row_elems, b.data(), row_elems, row_elems, patch,
                             std::numeric_limits<int64_t>::max()),
            expect);
  if (cpu_has_avx2()) {
    EXPECT_EQ(patch_ssd_avx2(a.data(), row_elems, b.data(), row_elems, row_elems, patch,
                             std::numeric_limits<int64_t>::max()),
              expect);
  }
}

// ---------------------------------------------------------------------------------------------
// Pyramid

TEST(Pyramid, ThinLineSurvivesDownsampling) {
  // A one-pixel vertical line at an odd column: decimation would drop it entirely.
  Image<float> im(64, 8, 1);
  for (int y = 0; y < 8; ++y) im(33, y) = 1.0f;
  Image<float> cur = im.clone();
  for (int level = 0; level < 3; ++level) cur = downsample(cur.cview());
  float peak = 0.0f, total = 0.0f;
  for (int y = 0; y < cur.height(); ++y)
    for (int x = 0; x < cur.width(); ++x) peak = std::max(peak, cur(x, y)), total += cur(x, y);
  EXPECT_GT(peak, 0.05f);
  // The filter keeps the mean: 8 line pixels over 64x8 -> mean 1/64.
  EXPECT_NEAR(total / float(cur.width() * cur.height()), 1.0f / 64.0f, 1e-3f);
}

TEST(Pyramid, ConstantStaysConstantAndSizesHalve) {
  Image<int16_t> im(37, 20, 8);
  im.fill(1234);
  Image<int16_t> d = downsample(im.cview());
  EXPECT_EQ(d.width(), 19);
  EXPECT_EQ(d.height(), 10);
  for (int y = 0; y < d.height(); ++y)
    for (int x = 0; x < d.width(); ++x)
      for (int c = 0; c < 8; ++c) ASSERT_EQ(d(x, y, c), 1234);
}

TEST(Pyramid, LevelCountFollowsPatchSize) {
  EXPECT_EQ(max_pyramid_levels(1200, 912, 1200, 912, 5), 7);
  EXPECT_EQ(max_pyramid_levels(20, 20, 20, 20, 5), 1);
}

// ---------------------------------------------------------------------------------------------
// Voting

TEST(Voting, ShiftedFieldReproducesShiftedSource) {
  const int w = 32, h = 24, p = 5, r = 2, shift = 3;
  Image<float> src = noise(w, h, 3, 11);
  Image<int32_t> nnf(w - 2 * shift, h, 2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < nnf.width(); ++x) {
      nnf(x, y, 0) = std::clamp(x + shift, r, w - r - 1);
      nnf(x, y, 1) = std::clamp(y, r, h - r - 1);
    }
  Image<float> err(nnf.width(), h, 1), out;
  for (VoteMode mode : {VoteMode::kPlain, VoteMode::kWeighted}) {
    vote(Plane(src.cview()), nnf, err, Image<uint8_t>(), p, mode, out);
    for (int y = 2 * r; y < h - 2 * r; ++y)
      for (int x = 2 * r; x < nnf.width() - 2 * r; ++x)
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(out(x, y, c), src(x + shift, y, c), 1e-6f);
  }
}

TEST(Voting, WeightedFavoursLowErrorPatches) {
  // Two source pixels values 0 and 1; pixel (2,2)'s patches all map to 0-valued pixels except
  // the patch centred on it, which maps to 1 and has zero error while the others have huge
  // error: weighted voting pulls toward 1, plain voting toward 0.
  const int w = 9, h = 9, p = 5;
  Image<float> src(w, h, 1);
  src(6, 6) = 1.0f;
  Image<int32_t> nnf(5, 5, 2);
  Image<float> err(5, 5, 1);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) {
      nnf(x, y, 0) = 2 + (x == 2 && y == 2 ? 4 : 0);
      nnf(x, y, 1) = 2 + (x == 2 && y == 2 ? 4 : 0);
      err(x, y) = (x == 2 && y == 2) ? 0.0f : 1e7f;
    }
  Image<float> plain, weighted;
  vote(Plane(src.cview()), nnf, err, Image<uint8_t>(), p, VoteMode::kPlain, plain);
  vote(Plane(src.cview()), nnf, err, Image<uint8_t>(), p, VoteMode::kWeighted, weighted);
  EXPECT_NEAR(plain(2, 2), 1.0f / 25.0f, 1e-6f);
  EXPECT_GT(weighted(2, 2), 0.9f);
}

// ---------------------------------------------------------------------------------------------
// Occupancy

TEST(Occupancy, WindowSumsMatchBruteForce) {
  const int sw = 20, sh = 16, tw = 12, th = 10, p = 5;
  Image<int32_t> nnf(tw, th, 2);
  CounterRng rng(3);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      nnf(x, y, 0) = 2 + int(rng.uniform(sw - 4));
      nnf(x, y, 1) = 2 + int(rng.uniform(sh - 4));
    }
  PatchMatchLevel L;
  L.sw = sw, L.sh = sh, L.tw = tw, L.th = th, L.nnf = &nnf;
  std::vector<int32_t> sums, scratch;
  occupancy_window_sums(L, p, sums, scratch);
  // Brute force: omega(s) = target patches covering s; window sum = sum of omega over the patch.
  std::vector<int> omega(sw * sh, 0);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x)
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) omega[(nnf(x, y, 1) + dy) * sw + nnf(x, y, 0) + dx]++;
  for (int cy = 2; cy < sh - 2; ++cy)
    for (int cx = 2; cx < sw - 2; ++cx) {
      int s = 0;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) s += omega[(cy + dy) * sw + cx + dx];
      ASSERT_EQ(sums[cy * sw + cx], s) << cx << "," << cy;
    }
}

// ---------------------------------------------------------------------------------------------
// Whole synthesis

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
    set_thread_count(threads);
    results.push_back(synthesize(f.inputs(), params, req));
  }
  set_thread_count(0);
  for (std::size_t i = 1; i < results.size(); ++i) {
    EXPECT_TRUE(same_bits(results[0].image, results[i].image)) << "run " << i;
    for (int y = 0; y < 72; ++y)
      ASSERT_EQ(0, std::memcmp(results[0].nnf.row(y), results[i].nnf.row(y), 120 * 2 * 4));
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
  Image<float> nan = noise(32, 32, 1, 4);
  nan(3, 4) = std::numeric_limits<float>::quiet_NaN();
  in = f.inputs();
  in.guides[0].source = nan.cview();
  EXPECT_THROW(validate(in, p), Error);
  Image<float> tiny(4, 4, 1);
  in = f.inputs();
  in.guides[0].target = tiny.cview();
  EXPECT_THROW(validate(in, p), Error);
}

}  // namespace
}  // namespace emaki::synth
