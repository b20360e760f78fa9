// AVX2 patch distance. Compiled with -mavx2; only called when the CPU has AVX2.
// Differences of int16 values in [0, 16383] fit int16; madd_epi16 sums two squares into an
// int32 (<= 2 * 16383^2). The plain kernel adds up to eight such sums in a lane taken as
// unsigned (8 * 2 * 16383^2 < 2^32), so a patch row of up to eight chunks (5x5 patches of 16
// channels: five) is widened to int64 once; the grouped kernel widens every three chunks. The
// total is exact either way.
#include <immintrin.h>

#include "synth/patch_distance.h"

namespace emaki::synth {

namespace {
inline __m256i widen_add(__m256i acc64, __m256i v32) {
  const __m256i lo = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(v32));
  const __m256i hi = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(v32, 1));
  return _mm256_add_epi64(acc64, _mm256_add_epi64(lo, hi));
}
// widen_add for lanes holding unsigned sums (below 2^32).
inline __m256i widen_add_unsigned(__m256i acc64, __m256i v32) {
  const __m256i lo = _mm256_cvtepu32_epi64(_mm256_castsi256_si128(v32));
  const __m256i hi = _mm256_cvtepu32_epi64(_mm256_extracti128_si256(v32, 1));
  return _mm256_add_epi64(acc64, _mm256_add_epi64(lo, hi));
}
inline int64_t hsum64(__m256i v) {
  const __m128i s = _mm_add_epi64(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
  return _mm_cvtsi128_si64(s) + _mm_extract_epi64(s, 1);
}
}  // namespace

namespace {

// Rows of row_elems elements: 16 per vector, then an 8-element tail. With E > 0 the width is
// known at compile time (E == row_elems): the row loop unrolls and the widening schedule folds
// away. Each 32-bit lane takes at most eight squared-pair sums before it is widened to int64.
template <int E>
[[gnu::always_inline]] inline int64_t ssd_rows(const int16_t* a, std::ptrdiff_t a_stride,
                                               const int16_t* b, std::ptrdiff_t b_stride,
                                               int row_elems, int rows, int64_t bound) {
  static_assert(E % 8 == 0 && E >= 0);
  const int n = E > 0 ? E : row_elems;
  const int full = n / 16;
  __m256i acc64 = _mm256_setzero_si256();
  for (int j = 0; j < rows; ++j) {
    const int16_t* pa = a + j * a_stride;
    const int16_t* pb = b + j * b_stride;
    __m256i acc32 = _mm256_setzero_si256();
#pragma GCC unroll 8
    for (int v = 0; v < full; ++v) {
      const __m256i va = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pa + 16 * v));
      const __m256i vb = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pb + 16 * v));
      const __m256i d = _mm256_sub_epi16(va, vb);
      acc32 = _mm256_add_epi32(acc32, _mm256_madd_epi16(d, d));
      if (v % 8 == 7) {
        acc64 = widen_add_unsigned(acc64, acc32);
        acc32 = _mm256_setzero_si256();
      }
    }
    if (n % 16 != 0) {  // an 8-element tail: the lane then holds at most full % 8 + 1 <= 8 sums
      const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pa + 16 * full));
      const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb + 16 * full));
      const __m128i d = _mm_sub_epi16(va, vb);
      acc32 = _mm256_add_epi32(acc32, _mm256_zextsi128_si256(_mm_madd_epi16(d, d)));
    }
    acc64 = widen_add_unsigned(acc64, acc32);
    if (j + 1 < rows) {
      const int64_t s = hsum64(acc64);
      if (s > bound) return s;
    }
  }
  return hsum64(acc64);
}

}  // namespace

int64_t patch_ssd_avx2(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                       std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound) {
  switch (row_elems) {
    case 24:  // 3x3 patches of 8 channels (the 3x3 pass)
      return ssd_rows<24>(a, a_stride, b, b_stride, row_elems, rows, bound);
    case 40:  // 5x5 patches of 8 channels
      return ssd_rows<40>(a, a_stride, b, b_stride, row_elems, rows, bound);
    case 48:
      return ssd_rows<48>(a, a_stride, b, b_stride, row_elems, rows, bound);
    case 80:  // 5x5 patches of 16 channels (StyLit's four RGB guides)
      return ssd_rows<80>(a, a_stride, b, b_stride, row_elems, rows, bound);
    case 120:
      return ssd_rows<120>(a, a_stride, b, b_stride, row_elems, rows, bound);
    default:
      return ssd_rows<0>(a, a_stride, b, b_stride, row_elems, rows, bound);
  }
}

namespace {

// The grouped kernel with the group count known at compile time, so the accumulators stay in
// registers. Each group's differences are its masked copy of the same difference vector.
template <int G>
int64_t grouped(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound,
                const int16_t* masks, std::ptrdiff_t mask_stride, const int64_t* weights) {
  __m256i acc64[G];
  for (int g = 0; g < G; ++g) acc64[g] = _mm256_setzero_si256();
  auto total = [&]() {
    int64_t s = 0;
    for (int g = 0; g < G; ++g) s += weights[g] * hsum64(acc64[g]);
    return s;
  };
  for (int j = 0; j < rows; ++j) {
    const int16_t* pa = a + j * a_stride;
    const int16_t* pb = b + j * b_stride;
    __m256i acc32[G];
    for (int g = 0; g < G; ++g) acc32[g] = _mm256_setzero_si256();
    int pending = 0;
    int i = 0;
    for (; i + 16 <= row_elems; i += 16) {
      const __m256i va = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pa + i));
      const __m256i vb = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(pb + i));
      const __m256i d = _mm256_sub_epi16(va, vb);
      for (int g = 0; g < G; ++g) {
        const __m256i m =
            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(masks + g * mask_stride + i));
        const __m256i dg = _mm256_and_si256(d, m);
        acc32[g] = _mm256_add_epi32(acc32[g], _mm256_madd_epi16(dg, dg));
      }
      if (++pending == 3) {
        for (int g = 0; g < G; ++g) {
          acc64[g] = widen_add(acc64[g], acc32[g]);
          acc32[g] = _mm256_setzero_si256();
        }
        pending = 0;
      }
    }
    if (i < row_elems) {  // an 8-element tail
      const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pa + i));
      const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb + i));
      const __m128i d = _mm_sub_epi16(va, vb);
      for (int g = 0; g < G; ++g) {
        const __m128i m =
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(masks + g * mask_stride + i));
        const __m128i dg = _mm_and_si128(d, m);
        const __m256i sq = _mm256_zextsi128_si256(_mm_madd_epi16(dg, dg));
        if (pending == 3) {
          acc64[g] = widen_add(acc64[g], acc32[g]);
          acc32[g] = _mm256_setzero_si256();
        }
        acc32[g] = _mm256_add_epi32(acc32[g], sq);
      }
    }
    for (int g = 0; g < G; ++g) acc64[g] = widen_add(acc64[g], acc32[g]);
    if (j + 1 < rows) {
      const int64_t s = total();
      if (s > bound) return s;
    }
  }
  return total();
}

}  // namespace

int64_t patch_ssd_grouped_avx2(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                               std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound,
                               const int16_t* masks, std::ptrdiff_t mask_stride,
                               const int64_t* weights, int groups) {
  using Fn = int64_t (*)(const int16_t*, std::ptrdiff_t, const int16_t*, std::ptrdiff_t, int, int,
                         int64_t, const int16_t*, std::ptrdiff_t, const int64_t*);
  static constexpr Fn kByCount[kMaxChannelGroups + 1] = {nullptr,    grouped<1>, grouped<2>,
                                                         grouped<3>, grouped<4>, grouped<5>,
                                                         grouped<6>, grouped<7>, grouped<8>};
  if (groups < 1 || groups > kMaxChannelGroups)
    return patch_ssd_grouped_scalar(a, a_stride, b, b_stride, row_elems, rows, bound, masks,
                                    mask_stride, weights, groups);
  return kByCount[groups](a, a_stride, b, b_stride, row_elems, rows, bound, masks, mask_stride,
                          weights);
}

}  // namespace emaki::synth
