// Patch distance: the sum of squared differences between two patches of int16 feature pixels,
// computed exactly in 64-bit integers (weights are folded into the data by
// ChannelMap in pyramid.h).
// A plain scalar version, an AVX2 version tested against it, and a dispatcher that picks one.
#pragma once

#include <cstddef>
#include <cstdint>

namespace emaki::synth {

// a, b: top-left element of each patch; strides in elements between rows; each patch row is
// `row_elems` contiguous int16 (patch width x channels, a multiple of 8); `rows` rows.
// Stops after any row once the running sum exceeds `bound` and returns that partial sum
// (which is then > bound).
using PatchSsdFn = int64_t (*)(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                               std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound);

int64_t patch_ssd_scalar(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                         std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound);
int64_t patch_ssd_avx2(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                       std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound);

bool cpu_has_avx2();
// The fastest kernel this CPU runs (EMAKI_SIMD=scalar in the environment forces scalar).
PatchSsdFn best_patch_ssd();

}  // namespace emaki::synth
