// AVX2 patch distance. Compiled with -mavx2; only called when the CPU has AVX2.
// Differences of int16 values in [0, 16383] fit int16; madd_epi16 sums two squares into an
// int32 (<= 2 * 16383^2). A patch row (an even number of elements: whole int16 pairs) is read as
// 16-element vectors, then a tail of its last row_elems % 16 elements, one pair per 32-bit lane
// and the lanes outside the tail zero. Nothing outside the row is read (see tail_keep). Each
// vector or tail adds at most one such sum to a lane. The plain kernel adds up to eight sums in a
// lane taken as unsigned (8 * 2 * 16383^2 < 2^32) before it widens to int64: every eight
// vectors, and the tail joins the at most full % 8 <= 7 sums since the last widening. The
// grouped kernel widens every three vectors (3 * 2 * 16383^2 < 2^31, signed), so the tail joins
// at most two. The total is exact either way.
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

// Tails other than 8 elements (those take 128-bit loads) are read so as never to pass the row's
// end, which may be where its memory ends: a row of 16 elements or more (`whole`) by its last 16,
// a whole vector inside the row, with the lanes before the tail (counted already) masked off; a
// shorter row by masked loads (VPMASKMOVD neither reads nor faults on masked-out lanes). `keep`
// enables the tail's lanes: tail_keep(whole, tail).
inline __m256i tail_keep(bool whole, int tail) {
  alignas(32) static constexpr int32_t kLanes[24] = {0,  0,  0,  0,  0, 0, 0, 0, -1, -1, -1, -1,
                                                     -1, -1, -1, -1, 0, 0, 0, 0, 0,  0,  0,  0};
  const int k = tail / 2;  // kLanes + k enables the last k lanes, kLanes + 16 - k the first k
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kLanes + (whole ? k : 16 - k)));
}
// The tail's elements of one row of row_elems (and, when whole, the ones before them).
[[gnu::always_inline]] inline __m256i tail_load(const int16_t* row, int row_elems, bool whole,
                                                __m256i keep) {
  if (whole) return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(row + row_elems - 16));
  return _mm256_maskload_epi32(reinterpret_cast<const int*>(row), keep);
}
// a - b over the tail of two rows, zero in the other lanes.
[[gnu::always_inline]] inline __m256i tail_diff(const int16_t* a, const int16_t* b, int row_elems,
                                                bool whole, __m256i keep) {
  return _mm256_and_si256(
      _mm256_sub_epi16(tail_load(a, row_elems, whole, keep), tail_load(b, row_elems, whole, keep)),
      keep);
}
}  // namespace

namespace {

// Rows of row_elems elements (even): row_elems / 16 whole 16-element vectors, then a tail of
// row_elems % 16. F and T, unless -1, are those two counts known at compile time: with F the
// vector loop unrolls and the widening schedule folds away, with T the choice of tail load does.
// Each 32-bit lane takes at most eight squared-pair sums before it is widened to int64.
template <int F, int T>
[[gnu::always_inline]] inline int64_t ssd_rows(const int16_t* a, std::ptrdiff_t a_stride,
                                               const int16_t* b, std::ptrdiff_t b_stride,
                                               int row_elems, int rows, int64_t bound) {
  static_assert(F >= -1 && T >= -1 && T < 16 && (T == -1 || T % 2 == 0));
  const int full = F >= 0 ? F : row_elems / 16, tail = T >= 0 ? T : row_elems % 16;
  const bool whole = full > 0;
  const __m256i keep = tail != 0 && tail != 8 ? tail_keep(whole, tail) : _mm256_setzero_si256();
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
    // The tail: the lane then holds at most full % 8 + 1 <= 8 sums.
    if (tail == 8) {
      const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pa + 16 * full));
      const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb + 16 * full));
      const __m128i d = _mm_sub_epi16(va, vb);
      acc32 = _mm256_add_epi32(acc32, _mm256_zextsi128_si256(_mm_madd_epi16(d, d)));
    } else if (tail != 0) {
      const __m256i d = tail_diff(pa, pb, row_elems, whole, keep);
      acc32 = _mm256_add_epi32(acc32, _mm256_madd_epi16(d, d));
    }
    acc64 = widen_add_unsigned(acc64, acc32);
    if (j + 1 < rows) {
      const int64_t s = hsum64(acc64);
      if (s > bound) return s;
    }
  }
  return hsum64(acc64);
}

// ssd_rows for rows of exactly E elements, and for rows of F whole vectors and any tail. Each
// width is a function of its own that patch_ssd_avx2 jumps to: inlined there, the widths that
// need many registers made every call save and restore them.
template <int E>
[[gnu::noinline]] int64_t ssd_fixed(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                                    std::ptrdiff_t b_stride, int rows, int64_t bound) {
  return ssd_rows<E / 16, E % 16>(a, a_stride, b, b_stride, E, rows, bound);
}
template <int F>
[[gnu::noinline]] int64_t ssd_vectors(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                                      std::ptrdiff_t b_stride, int row_elems, int rows,
                                      int64_t bound) {
  return ssd_rows<F, -1>(a, a_stride, b, b_stride, row_elems, rows, bound);
}

}  // namespace

int64_t patch_ssd_avx2(const int16_t* a, std::ptrdiff_t a_stride, const int16_t* b,
                       std::ptrdiff_t b_stride, int row_elems, int rows, int64_t bound) {
  // The widths of common layouts, known at compile time.
  switch (row_elems) {
    case 20:  // 5x5 patches of 4 channels (an RGB style and a gray guide)
      return ssd_fixed<20>(a, a_stride, b, b_stride, rows, bound);
    case 24:  // 3x3 patches of 8 channels (the 3x3 pass)
      return ssd_fixed<24>(a, a_stride, b, b_stride, rows, bound);
    case 30:  // 5x5 patches of 6 channels (an RGB style and an RGB guide)
      return ssd_fixed<30>(a, a_stride, b, b_stride, rows, bound);
    case 40:  // 5x5 patches of 8 channels
      return ssd_fixed<40>(a, a_stride, b, b_stride, rows, bound);
    case 48:  // 3x3 patches of 16 channels
      return ssd_fixed<48>(a, a_stride, b, b_stride, rows, bound);
    case 50:  // 5x5 patches of 10 channels (FaceStyle: an RGB style, a gray and two RGB guides)
      return ssd_fixed<50>(a, a_stride, b, b_stride, rows, bound);
    case 70:  // 5x5 patches of 14 channels (StyLit: an RGB style, three RGB and a gray guide)
      return ssd_fixed<70>(a, a_stride, b, b_stride, rows, bound);
    case 80:  // 5x5 patches of 16 channels
      return ssd_fixed<80>(a, a_stride, b, b_stride, rows, bound);
    case 120:  // 5x5 patches of 24 channels
      return ssd_fixed<120>(a, a_stride, b, b_stride, rows, bound);
  }
  // Other widths up to 127: the whole vectors known at compile time (5x5 patches of up to 24
  // channels, 7x7 of up to 18), the tail's length not.
  using Fn = int64_t (*)(const int16_t*, std::ptrdiff_t, const int16_t*, std::ptrdiff_t, int, int,
                         int64_t);
  static constexpr Fn kByVectors[8] = {ssd_vectors<0>, ssd_vectors<1>, ssd_vectors<2>,
                                       ssd_vectors<3>, ssd_vectors<4>, ssd_vectors<5>,
                                       ssd_vectors<6>, ssd_vectors<7>};
  const Fn f = row_elems / 16 < 8 ? kByVectors[row_elems / 16] : ssd_vectors<-1>;
  return f(a, a_stride, b, b_stride, row_elems, rows, bound);
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
  const int tail = row_elems % 16;
  const bool whole = row_elems >= 16;
  const __m256i keep = tail != 0 && tail != 8 ? tail_keep(whole, tail) : _mm256_setzero_si256();
  for (int j = 0; j < rows; ++j) {
    const int16_t* pa = a + j * a_stride;
    const int16_t* pb = b + j * b_stride;
    __m256i acc32[G];
    for (int g = 0; g < G; ++g) acc32[g] = _mm256_setzero_si256();
    int pending = 0;  // vectors summed in acc32 since the last widening
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
    // The tail (pending < 3: the lane then holds at most three sums). The mask rows are read as
    // the patch rows are; the difference is zero outside the tail already.
    if (tail == 8) {
      const __m128i va = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pa + i));
      const __m128i vb = _mm_loadu_si128(reinterpret_cast<const __m128i*>(pb + i));
      const __m128i d = _mm_sub_epi16(va, vb);
      for (int g = 0; g < G; ++g) {
        const __m128i m =
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(masks + g * mask_stride + i));
        const __m128i dg = _mm_and_si128(d, m);
        acc32[g] = _mm256_add_epi32(acc32[g], _mm256_zextsi128_si256(_mm_madd_epi16(dg, dg)));
      }
    } else if (tail != 0) {
      const __m256i d = tail_diff(pa, pb, row_elems, whole, keep);
      for (int g = 0; g < G; ++g) {
        const __m256i dg =
            _mm256_and_si256(d, tail_load(masks + g * mask_stride, row_elems, whole, keep));
        acc32[g] = _mm256_add_epi32(acc32[g], _mm256_madd_epi16(dg, dg));
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
