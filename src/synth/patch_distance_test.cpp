// Patch distance kernels: the AVX2 kernel equals the scalar one bit for bit, and sums are exact.
#include "synth/patch_distance.h"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/check.h"
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

// `count` int16 ending exactly where readable memory does: the page after them is mapped without
// access, so a kernel that reads past a row's last element faults in any build (an ASan build
// would catch it in an exactly sized std::vector too, a release build would not).
class GuardedBuffer {
 public:
  explicit GuardedBuffer(std::size_t count) {
    const std::size_t page = std::size_t(sysconf(_SC_PAGESIZE));
    const std::size_t bytes = count * sizeof(int16_t), pages = (bytes + page - 1) / page;
    size_ = (pages + 1) * page;
    void* base = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    CHECK(base != MAP_FAILED);
    base_ = static_cast<char*>(base);
    CHECK_EQ(mprotect(base_ + pages * page, page, PROT_NONE), 0);
    data_ = reinterpret_cast<int16_t*>(base_ + pages * page - bytes);
    count_ = count;
  }
  GuardedBuffer(const GuardedBuffer&) = delete;
  GuardedBuffer& operator=(const GuardedBuffer&) = delete;
  ~GuardedBuffer() { munmap(base_, size_); }
  int16_t* data() { return data_; }
  int16_t* begin() { return data_; }
  int16_t* end() { return data_ + count_; }

 private:
  char* base_ = nullptr;
  std::size_t size_ = 0, count_ = 0;
  int16_t* data_ = nullptr;
};

// Patch rows as FeatureLayout gives them (patch width x an even channel count): most not a
// multiple of 8 or 16, the compile-time cases of patch_ssd_avx2, and tails after 7 and 8 whole
// vectors (a lane's eighth sum before widening, and the first after it).
constexpr int kEvenRowElems[] = {2,  4,  6,  10, 12, 14, 18, 20, 24,  28,  30,  36,
                                 40, 42, 48, 50, 60, 70, 80, 90, 114, 120, 126, 142};

TEST(PatchDistance, Avx2EqualsScalarForEvenRowsEndingAtTheMemory) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  CounterRng rng(13);
  const int64_t max = std::numeric_limits<int64_t>::max();
  for (int row_elems : kEvenRowElems) {
    for (int rows : {1, 3, 5}) {
      // Rows packed end to end, and rows apart at an odd pair count (as pixels of a padded image).
      for (std::ptrdiff_t stride : {std::ptrdiff_t(row_elems), std::ptrdiff_t(row_elems) + 6}) {
        const std::size_t count = std::size_t(stride) * (rows - 1) + row_elems;
        GuardedBuffer a(count), b(count);
        for (int trial = 0; trial < 20; ++trial) {
          for (int16_t& v : a) v = int16_t(rng.uniform(kQuantMax + 1));
          for (int16_t& v : b) v = int16_t(rng.uniform(kQuantMax + 1));
          if (trial == 0) std::fill(a.begin(), a.end(), int16_t(kQuantMax));  // worst case
          if (trial == 0) std::fill(b.begin(), b.end(), int16_t(0));
          const int64_t full =
              patch_ssd_scalar(a.data(), stride, b.data(), stride, row_elems, rows, max);
          const int64_t bound = trial % 2 ? full / 3 : max;
          EXPECT_EQ(patch_ssd_scalar(a.data(), stride, b.data(), stride, row_elems, rows, bound),
                    patch_ssd_avx2(a.data(), stride, b.data(), stride, row_elems, rows, bound))
              << "row_elems " << row_elems << " rows " << rows << " stride " << stride << " trial "
              << trial;
        }
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

// Masks for `groups` groups over a pixel of `channels` elements repeated `patch` times: channel c
// belongs to group group_of[c].
std::vector<int16_t> group_masks(const std::vector<int>& group_of, int patch, int groups) {
  const int channels = int(group_of.size()), row_elems = patch * channels;
  std::vector<int16_t> m(std::size_t(groups) * row_elems, 0);
  for (int g = 0; g < groups; ++g)
    for (int i = 0; i < row_elems; ++i)
      if (group_of[i % channels] == g) m[std::size_t(g) * row_elems + i] = -1;
  return m;
}

TEST(PatchDistance, GroupedAvx2EqualsScalar) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  CounterRng rng(11);
  for (int channels : {8, 16, 24}) {
    for (int patch : {3, 5, 7}) {
      for (int groups = 1; groups <= kMaxChannelGroups; ++groups) {
        std::vector<int> group_of(channels);
        for (int& g : group_of) g = int(rng.uniform(uint32_t(groups)));
        const int row_elems = patch * channels;
        const std::vector<int16_t> masks = group_masks(group_of, patch, groups);
        const std::ptrdiff_t stride = row_elems + 24;
        std::vector<int16_t> a(stride * patch), b(stride * patch);
        for (int trial = 0; trial < 20; ++trial) {
          for (auto& v : a) v = int16_t(rng.uniform(kQuantMax + 1));
          for (auto& v : b) v = int16_t(rng.uniform(kQuantMax + 1));
          int64_t w[kMaxChannelGroups];
          for (int g = 0; g < groups; ++g)
            w[g] = trial == 0 ? 65536 : int64_t(rng.uniform(65537));  // 0 .. 2^16
          const int64_t full = patch_ssd_grouped_scalar(
              a.data(), stride, b.data(), stride, row_elems, patch,
              std::numeric_limits<int64_t>::max(), masks.data(), row_elems, w, groups);
          const int64_t bound = trial % 2 ? full / 3 : std::numeric_limits<int64_t>::max();
          EXPECT_EQ(patch_ssd_grouped_scalar(a.data(), stride, b.data(), stride, row_elems, patch,
                                             bound, masks.data(), row_elems, w, groups),
                    patch_ssd_grouped_avx2(a.data(), stride, b.data(), stride, row_elems, patch,
                                           bound, masks.data(), row_elems, w, groups))
              << "channels " << channels << " patch " << patch << " groups " << groups << " trial "
              << trial;
        }
      }
    }
  }
}

TEST(PatchDistance, GroupedAvx2EqualsScalarForEvenRowsEndingAtTheMemory) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  CounterRng rng(17);
  const int64_t max = std::numeric_limits<int64_t>::max();
  for (int channels : {2, 4, 6, 10, 12, 14, 18}) {
    for (int patch : {1, 3, 5, 7}) {
      for (int groups : {1, 2, 3, 5, kMaxChannelGroups}) {
        std::vector<int> group_of(channels);
        for (int& g : group_of) g = int(rng.uniform(uint32_t(groups)));
        const int row_elems = patch * channels;
        const std::vector<int16_t> m = group_masks(group_of, patch, groups);
        GuardedBuffer masks(m.size());  // the last group's row ends at the memory's end
        std::copy(m.begin(), m.end(), masks.begin());
        const std::size_t count = std::size_t(row_elems) * patch;
        GuardedBuffer a(count), b(count);
        for (int trial = 0; trial < 10; ++trial) {
          for (int16_t& v : a) v = int16_t(rng.uniform(kQuantMax + 1));
          for (int16_t& v : b) v = int16_t(rng.uniform(kQuantMax + 1));
          if (trial == 0) std::fill(a.begin(), a.end(), int16_t(kQuantMax));  // worst case
          if (trial == 0) std::fill(b.begin(), b.end(), int16_t(0));
          int64_t w[kMaxChannelGroups];
          for (int g = 0; g < groups; ++g) w[g] = trial == 0 ? 65536 : int64_t(rng.uniform(65537));
          const int64_t full =
              patch_ssd_grouped_scalar(a.data(), row_elems, b.data(), row_elems, row_elems, patch,
                                       max, masks.data(), row_elems, w, groups);
          const int64_t bound = trial % 2 ? full / 3 : max;
          EXPECT_EQ(patch_ssd_grouped_scalar(a.data(), row_elems, b.data(), row_elems, row_elems,
                                             patch, bound, masks.data(), row_elems, w, groups),
                    patch_ssd_grouped_avx2(a.data(), row_elems, b.data(), row_elems, row_elems,
                                           patch, bound, masks.data(), row_elems, w, groups))
              << "channels " << channels << " patch " << patch << " groups " << groups << " trial "
              << trial;
        }
      }
    }
  }
}

// Every group at weight w is the plain distance times w; a group at weight 0 drops out.
TEST(PatchDistance, GroupedWeightsScaleAndDropGroups) {
  CounterRng rng(3);
  const int channels = 8, patch = 5, row_elems = patch * channels;
  const std::vector<int> group_of = {0, 0, 0, 1, 1, 1, 0, 0};
  const std::vector<int16_t> masks = group_masks(group_of, patch, 2);
  std::vector<int16_t> a(row_elems * patch), b(row_elems * patch), b_without(row_elems * patch);
  for (auto& v : a) v = int16_t(rng.uniform(kQuantMax + 1));
  for (auto& v : b) v = int16_t(rng.uniform(kQuantMax + 1));
  for (std::size_t i = 0; i < b.size(); ++i)
    b_without[i] = group_of[i % channels] == 1 ? a[i] : b[i];  // group 1 equal: no difference
  const int64_t max = std::numeric_limits<int64_t>::max();
  const int64_t plain =
      patch_ssd_scalar(a.data(), row_elems, b.data(), row_elems, row_elems, patch, max);
  const int64_t base_only =
      patch_ssd_scalar(a.data(), row_elems, b_without.data(), row_elems, row_elems, patch, max);
  const int64_t same[2] = {65536, 65536}, drop[2] = {65536, 0};
  for (PatchSsdGroupedFn fn : {patch_ssd_grouped_scalar, best_patch_ssd_grouped()}) {
    EXPECT_EQ(fn(a.data(), row_elems, b.data(), row_elems, row_elems, patch, max, masks.data(),
                 row_elems, same, 2),
              65536 * plain);
    EXPECT_EQ(fn(a.data(), row_elems, b.data(), row_elems, row_elems, patch, max, masks.data(),
                 row_elems, drop, 2),
              65536 * base_only);
  }
}

TEST(PatchDistance, GroupedExactForLargestDifferences) {
  const int patch = 9, channels = 32, row_elems = patch * channels;
  std::vector<int> group_of(channels);
  for (int c = 0; c < channels; ++c) group_of[c] = c % 4;
  const std::vector<int16_t> masks = group_masks(group_of, patch, 4);
  std::vector<int16_t> a(row_elems * patch, kQuantMax), b(row_elems * patch, 0);
  const int64_t w[4] = {65536, 65536, 65536, 65536};
  const int64_t expect = 65536 * int64_t(patch) * row_elems * int64_t(kQuantMax) * kQuantMax;
  EXPECT_EQ(
      patch_ssd_grouped_scalar(a.data(), row_elems, b.data(), row_elems, row_elems, patch,
                               std::numeric_limits<int64_t>::max(), masks.data(), row_elems, w, 4),
      expect);
  if (cpu_has_avx2()) {
    EXPECT_EQ(
        patch_ssd_grouped_avx2(a.data(), row_elems, b.data(), row_elems, row_elems, patch,
                               std::numeric_limits<int64_t>::max(), masks.data(), row_elems, w, 4),
        expect);
  }
}

}  // namespace
}  // namespace emaki::synth
