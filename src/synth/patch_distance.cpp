#include "synth/patch_distance.h"

#include "core/check.h"
#include "core/performance.h"

namespace emaki::synth {

int64_t patch_ssd_scalar(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                         std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound) {
  int64_t sum = 0;
  for (int j = 0; j < rows; ++j) {
    const int16_t* pa = a + j * a_stride;
    const int16_t* pb = b + j * b_stride;
    int64_t row = 0;
    for (int i = 0; i < row_elems; ++i) {
      const int32_t d = int32_t(pa[i]) - int32_t(pb[i]);
      row += int64_t(d) * d;
    }
    sum += row;
    if (sum > bound) break;
  }
  return sum;
}

int64_t patch_ssd_grouped_scalar(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                                 std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound,
                                 const int16_t* masks, std::ptrdiff_t mask_stride,
                                 const int64_t* weights, int groups) {
  CHECK(groups >= 1 && groups <= kMaxChannelGroups);
  int64_t group_sum[kMaxChannelGroups] = {};
  int64_t total = 0;
  for (int j = 0; j < rows; ++j) {
    const int16_t* pa = a + j * a_stride;
    const int16_t* pb = b + j * b_stride;
    for (int i = 0; i < row_elems; ++i) {
      const int32_t d = int32_t(pa[i]) - int32_t(pb[i]);
      for (int g = 0; g < groups; ++g)
        if (masks[g * mask_stride + i]) group_sum[g] += int64_t(d) * d;
    }
    total = 0;
    for (int g = 0; g < groups; ++g) total += weights[g] * group_sum[g];
    if (total > bound) break;
  }
  return total;
}

bool cpu_has_avx2() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

PatchSsdFn best_patch_ssd() {
  if (!performance().simd) return patch_ssd_scalar;
  return cpu_has_avx2() ? patch_ssd_avx2 : patch_ssd_scalar;
}

PatchSsdGroupedFn best_patch_ssd_grouped() {
  if (!performance().simd) return patch_ssd_grouped_scalar;
  return cpu_has_avx2() ? patch_ssd_grouped_avx2 : patch_ssd_grouped_scalar;
}

}  // namespace emaki::synth
