// Patch distance kernels: the AVX2 kernel equals the scalar one bit for bit, and sums are exact.
#include "synth/patch_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "synth/pyramid.h"
#include "synth/test_images.h"

namespace emaki::synth {
namespace {

using namespace test;

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

}  // namespace
}  // namespace emaki::synth
