// Patch distance: the sum of squared differences between two patches of int16 feature pixels,
// computed exactly in 64-bit integers (weights are folded into the data by
// ChannelMap in pyramid.h).
// A plain scalar version, an AVX2 version tested against it, and a dispatcher that picks one.
#pragma once

#include <cstddef>
#include <cstdint>

namespace emaki::synth {

// a, b: top-left element of each patch; strides in elements between rows; each patch row is
// `row_elems` contiguous int16 (patch width x channels, an even count: FeatureLayout pads pixels
// to whole int16 pairs); `rows` rows. Nothing past a row's last element is read, so a row may end
// where its memory does.
// Stops after any row once the running sum exceeds `bound` and returns that partial sum
// (which is then > bound).
using PatchSsdFn = int64_t (*)(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                               std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound);

int64_t patch_ssd_scalar(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                         std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound);
int64_t patch_ssd_avx2(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                       std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound);

// Channel groups, for guides whose weight varies per target pixel: every element of a patch row
// belongs to one of `groups` groups (`masks` holds `groups` rows of at least `row_elems` int16,
// row g at masks + g * mask_stride: -1 where the element is in group g, 0 elsewhere), and group
// g's sum of squared differences counts weights[g] times (1 <= groups <= kMaxChannelGroups).
// Returns sum_g weights[g] * ssd_g, exact in 64 bits (callers keep weights[g] <= 2^16 and patches
// below 2^46 per group); stops like PatchSsdFn after any row once that weighted sum exceeds
// `bound`.
inline constexpr int kMaxChannelGroups = 8;
inline constexpr int64_t kGroupWeightOne = int64_t(1) << 16;  // a group's full weight
using PatchSsdGroupedFn = int64_t (*)(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                                      std::ptrdiff_t b_stride, int row_elems, int rows,
                                      int64_t bound, const int16_t* masks,
                                      std::ptrdiff_t mask_stride, const int64_t* weights,
                                      int groups);

int64_t patch_ssd_grouped_scalar(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                                 std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound,
                                 const int16_t* masks, std::ptrdiff_t mask_stride,
                                 const int64_t* weights, int groups);
int64_t patch_ssd_grouped_avx2(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                               std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound,
                               const int16_t* masks, std::ptrdiff_t mask_stride,
                               const int64_t* weights, int groups);

bool cpu_has_avx2();
// The fastest kernel this CPU runs; the scalar one when performance().simd is off
// (core/performance.h: a front end's EMAKI_SIMD=scalar).
PatchSsdFn best_patch_ssd();
PatchSsdGroupedFn best_patch_ssd_grouped();

}  // namespace emaki::synth
