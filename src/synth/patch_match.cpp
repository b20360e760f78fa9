#include "synth/patch_match.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/check.h"
#include "core/parallel.h"
#include "core/rng.h"

namespace emaki::synth {

namespace {

inline bool is_active(const PatchMatchLevel& L, int x, int y) {
  return L.active == nullptr || L.active->empty() || (*L.active)(x, y) != 0;
}

// ---------------------------------------------------------------------------------------------
// Occupancy

// The weights (p - |dx|) * (p - |dy|), |dx|, |dy| < p, row by row: (2p - 1)^2 values.
std::vector<int32_t> triangle_table(int p) {
  const int n = 2 * p - 1;
  std::vector<int32_t> t(std::size_t(n) * n);
  for (int dy = 0; dy < n; ++dy)
    for (int dx = 0; dx < n; ++dx)
      t[std::size_t(dy) * n + dx] = (p - std::abs(dy - (p - 1))) * (p - std::abs(dx - (p - 1)));
  return t;
}

// Adds (Sign > 0) or subtracts the triangle (p - |dx|) * (p - |dy|) around source centre
// (cx, cy): the change of the window sums when one target patch starts or stops covering the
// patch at that centre. `table` is triangle_table(p); each row adds a table row, four lanes at a
// time (a multiply per element, scalar, was ~16 % of a MatCap pair's instructions).
template <int Sign>
void add_triangle(int32_t* buf, int sw, int sh, int cx, int cy, int p, const int32_t* table) {
  const int reach = p - 1, n = 2 * p - 1;
  const int y0 = std::max(0, cy - reach), y1 = std::min(sh - 1, cy + reach);
  const int x0 = std::max(0, cx - reach), x1 = std::min(sw - 1, cx + reach);
  const int len = x1 - x0 + 1;
  for (int y = y0; y <= y1; ++y) {
    const int32_t* w = table + std::ptrdiff_t(y - cy + reach) * n + (x0 - cx + reach);
    int32_t* row = buf + std::ptrdiff_t(y) * sw + x0;
    int i = 0;
#if defined(__SSE2__)
    if (len == 9) {  // 5x5 patches away from the source's edge: two vectors and one element
      const __m128i a0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row));
      const __m128i b0 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w));
      const __m128i a1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + 4));
      const __m128i b1 = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w + 4));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row),
                       Sign > 0 ? _mm_add_epi32(a0, b0) : _mm_sub_epi32(a0, b0));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row + 4),
                       Sign > 0 ? _mm_add_epi32(a1, b1) : _mm_sub_epi32(a1, b1));
      row[8] += Sign > 0 ? w[8] : -w[8];
      continue;
    }
    for (; i + 4 <= len; i += 4) {
      const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(row + i));
      const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(w + i));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row + i),
                       Sign > 0 ? _mm_add_epi32(a, b) : _mm_sub_epi32(a, b));
    }
#endif
    for (; i < len; ++i) row[i] += Sign > 0 ? w[i] : -w[i];
  }
}

// A band-private occupancy delta, zero between uses. Pooled so that a sweep allocates no
// source-sized buffers; which buffer a band gets does not matter since each starts at zero.
struct DeltaBuffers {
  std::vector<int32_t> delta;
  std::vector<uint8_t> dirty;
};

class DeltaPool {
 public:
  DeltaPool(std::size_t n, std::size_t blocks) : n_(n), blocks_(blocks) {}
  DeltaBuffers take() {
    std::lock_guard lock(mutex_);
    if (free_.empty()) return {std::vector<int32_t>(n_, 0), std::vector<uint8_t>(blocks_, 0)};
    auto v = std::move(free_.back());
    free_.pop_back();
    return v;
  }
  void give(DeltaBuffers&& v) {
    std::lock_guard lock(mutex_);
    free_.push_back(std::move(v));
  }

 private:
  std::size_t n_, blocks_;
  std::mutex mutex_;
  std::vector<DeltaBuffers> free_;
};

struct Sweep {
  const PatchMatchLevel& L;
  const PatchMatchConfig& C;
  const int32_t* occ;  // window sums as the round began, sw x sh
  float occ_scale;     // uniformity / (p^2 * omega_best)
  int r;
  std::ptrdiff_t src_stride;
  int row_elems;
  double inv_err_scale;
  const int32_t* triangle;  // triangle_table(2r + 1)
};

// Occupancy deltas are tracked per 8x8 block of source centres: most candidates land in blocks
// the band never touched, and a glance at this small map saves a cache miss in the big one.
inline constexpr int kDirtyShift = 3;

struct Band {
  int32_t* delta;
  uint8_t* dirty;  // per block: has the delta any non-zero value there
  int dirty_stride;
};

// Adds a band's occupancy delta to the window sums `occ` (when not null) and zeroes it, over the
// rows of 8x8 blocks [by0, by1), touching only the blocks the band dirtied. The delta is the exact
// change of the sums, so folding it in equals recomputing them from the field.
void fold_band(DeltaBuffers& buf, int dirty_stride, int32_t* occ, int sw, int sh, int by0,
               int by1) {
  const int bw = (sw + (1 << kDirtyShift) - 1) >> kDirtyShift;
  for (int by = by0; by < by1; ++by)
    for (int bx = 0; bx < bw; ++bx) {
      uint8_t& d = buf.dirty[std::size_t(by) * dirty_stride + bx];
      if (!d) continue;
      d = 0;
      const int x0 = bx << kDirtyShift, x1 = std::min(sw, x0 + (1 << kDirtyShift));
      const int y0 = by << kDirtyShift, y1 = std::min(sh, y0 + (1 << kDirtyShift));
      for (int y = y0; y < y1; ++y) {
        int32_t* delta = buf.delta.data() + std::ptrdiff_t(y) * sw;
        int32_t* sums = occ ? occ + std::ptrdiff_t(y) * sw : nullptr;
        for (int x = x0; x < x1; ++x) {
          if (sums) sums[x] += delta[x];
          delta[x] = 0;
        }
      }
    }
}

inline int32_t stored_occupancy(const Sweep& S, const Band& band, int cx, int cy) {
  const std::ptrdiff_t i = std::ptrdiff_t(cy) * S.L.sw + cx;
  const bool dirty = band.dirty[(cy >> kDirtyShift) * band.dirty_stride + (cx >> kDirtyShift)];
  return S.occ[i] + (dirty ? band.delta[i] : 0);
}

// The weight (p - |dx|) * (p - |dy|) with which a patch centred d away counts in a window sum.
inline int32_t triangle_weight(int dx, int dy, int p) {
  dx = std::abs(dx), dy = std::abs(dy);
  return dx < p && dy < p ? (p - dx) * (p - dy) : 0;
}

// The pixel being swept moves its match from `from` (what the stored sums count) to `to` only
// when it is done with its candidates (PixelMove): until then the occupancy at (cx, cy) is the
// stored one with the pixel's own patch moved by hand, which is the same integer as updating the
// sums at every accepted candidate, at a fraction of the cost (on the MatCap pairs a pixel
// accepts ~2.4 candidates per sweep at the finest level, each move two triangles of (2p - 1)^2).
struct PixelMove {
  int from_x, from_y, to_x, to_y;
};

inline float occupancy(const Sweep& S, const Band& band, int cx, int cy, const PixelMove& mv) {
  if (!(S.occ_scale > 0.0f)) return 0.0f;  // no uniformity term: no window sum to look up
  int32_t v = stored_occupancy(S, band, cx, cy);
  if (mv.to_x != mv.from_x || mv.to_y != mv.from_y) {
    const int p = 2 * S.r + 1;
    v += triangle_weight(cx - mv.to_x, cy - mv.to_y, p) -
         triangle_weight(cx - mv.from_x, cy - mv.from_y, p);
  }
  return S.occ_scale * float(v);
}

void mark_dirty(Band& band, int sw, int sh, int cx, int cy, int p) {
  const int reach = p - 1;
  const int bx0 = std::max(0, cx - reach) >> kDirtyShift,
            bx1 = std::min(sw - 1, cx + reach) >> kDirtyShift;
  const int by0 = std::max(0, cy - reach) >> kDirtyShift,
            by1 = std::min(sh - 1, cy + reach) >> kDirtyShift;
  for (int by = by0; by <= by1; ++by)
    for (int bx = bx0; bx <= bx1; ++bx) band.dirty[by * band.dirty_stride + bx] = 1;
}

// Brings a candidate's source patch and occupancy into cache ahead of its evaluation: the
// patches of random candidates are scattered over the exemplar, and fetching them all at once
// overlaps their memory latencies.
inline void prefetch_candidate(const Sweep& S, const Band& band, int cx, int cy) {
  const std::ptrdiff_t i = std::ptrdiff_t(cy) * S.L.sw + cx;
  if (S.occ_scale > 0.0f) {
    __builtin_prefetch(S.occ + i);
    if (band.dirty[(cy >> kDirtyShift) * band.dirty_stride + (cx >> kDirtyShift)])
      __builtin_prefetch(band.delta + i);
  }
  const int16_t* s = S.L.src->at(cx - S.r, cy - S.r);
  const int row_bytes = S.row_elems * int(sizeof(int16_t));
  for (int j = 0; j <= 2 * S.r; ++j) {
    const char* row = reinterpret_cast<const char*>(s + j * S.src_stride);
    for (int b = 0; b < row_bytes; b += 64) __builtin_prefetch(row + b);
    __builtin_prefetch(row + row_bytes - 1);
  }
}

// The target pixel being swept: its field entry, its error and its patch (top-left element).
struct PixelRefs {
  int x, y;
  int32_t* n;
  float* e;
  const int16_t* t;
  float occ_weight;  // PatchMatchLevel::uniformity_map at the pixel
};

// PatchMatchLevel::uniformity_map at target pixel (x, y), 1 without one.
inline float occupancy_weight(const PatchMatchLevel& L, int x, int y) {
  return L.uniformity_map && !L.uniformity_map->empty() ? (*L.uniformity_map)(x, y) : 1.0f;
}

// Tries source centre (cx, cy) for target pixel `px`; cur_occ is the occupancy cost of the
// pixel's current match. A taken candidate becomes the match and the end of `mv`.
inline void try_candidate(const Sweep& S, Band& band, const PixelRefs& px, int cx, int cy,
                          PixelMove& mv, float& cur_occ) {
  const PatchMatchLevel& L = S.L;
  int32_t* n = px.n;
  if (cx == n[0] && cy == n[1]) return;
  const float new_occ = occupancy(S, band, cx, cy, mv) * px.occ_weight;
  float& e = *px.e;
  const float cur_cost = e + cur_occ;
  const float bound = cur_cost - new_occ;
  if (!(bound > 0.0f)) return;
  // bound > 0, so truncation is the floor (without SSE4.1 std::floor is a library call).
  const double bq = double(bound) * S.inv_err_scale;
  const int64_t bound_q = bq > 9.0e18 ? std::numeric_limits<int64_t>::max() : int64_t(bq);
  const int16_t* s = L.src->at(cx - S.r, cy - S.r);
  const int64_t ssd =
      patch_distance(L, S.C, px.x, px.y, px.t, s, S.row_elems, 2 * S.r + 1, bound_q);
  if (ssd > bound_q) return;
  const float new_err = float(double(ssd) * S.C.err_scale);
  if (!(new_err + new_occ < cur_cost)) return;
  if (S.occ_scale > 0.0f) {
    mv.to_x = cx, mv.to_y = cy;
    cur_occ = occupancy(S, band, cx, cy, mv) * px.occ_weight;
  }
  n[0] = cx;
  n[1] = cy;
  e = new_err;
}

// Tries the k-coherence set of source centre (bx, by) (PatchMatchConfig::coherence), which
// only the source decides: no band writes it.
inline void try_set(const Sweep& S, Band& band, const PixelRefs& px, int bx, int by, PixelMove& mv,
                    float& cur_occ) {
  const CoherenceSets& sets = *S.C.coherence;
  const int32_t* set = sets.at(bx, by);
  for (int i = 0; i < sets.k && set[i] >= 0; ++i)
    try_candidate(S, band, px, set[i] % S.L.sw, set[i] / S.L.sw, mv, cur_occ);
}

// Whether a sweep searches for target pixel (x, y): inside the mask and, without a uniformity
// term, not matched exactly already (no candidate can cost less than 0; passing the pixel over,
// its draws skipped, changes no other pixel's draws).
inline bool searched(const Sweep& S, int x, int y) {
  return is_active(S.L, x, y) && (S.occ_scale > 0.0f || *S.L.err->at(x, y) != 0.0f);
}

void sweep_band(const Sweep& S, Band& band, int y0, int y1, int iter) {
  const PatchMatchLevel& L = S.L;
  const bool forward = (iter % 2) == 0;
  const int q = forward ? 1 : -1;
  const int r = S.r;
  const int lo_x = r, hi_x = L.sw - r - 1, lo_y = r, hi_y = L.sh - r - 1;
  const int max_rad = S.C.max_search_radius > 0 ? S.C.max_search_radius : std::max(L.sw, L.sh);
  int radii[32];
  int num_radii = 0;
  for (int rad = max_rad; rad >= 1 && num_radii < 32; rad /= 2) radii[num_radii++] = rad;
  const int ys = forward ? y0 : y1 - 1, ye = forward ? y1 : y0 - 1;
  const int xs = forward ? 0 : L.tw - 1, xe = forward ? L.tw : -1;
  // Random candidates are drawn one pixel ahead, around that pixel's match as the sweep found
  // it, and their patches prefetched, so their memory latency overlaps this pixel's work.
  int cand[2][32][2];
  auto draw = [&](int x, int y, int(*out)[2]) {
    const int32_t* n = L.nnf->at(x, y);
    CounterRng rng(hash_key(S.C.seed, uint64_t(iter), uint64_t(y) * 65536u + uint64_t(x)));
    for (int k = 0; k < num_radii; ++k) {
      const int rad = radii[k];
      const int wx0 = std::max(lo_x, n[0] - rad), wx1 = std::min(hi_x, n[0] + rad);
      const int wy0 = std::max(lo_y, n[1] - rad), wy1 = std::min(hi_y, n[1] + rad);
      out[k][0] = wx0 + int(rng.uniform(uint32_t(wx1 - wx0 + 1)));
      out[k][1] = wy0 + int(rng.uniform(uint32_t(wy1 - wy0 + 1)));
      prefetch_candidate(S, band, out[k][0], out[k][1]);
    }
  };
  const bool kcoh = S.C.coherence != nullptr;
  // Outside a target mask nothing is drawn: the draws are keyed by pixel, so skipping them changes
  // no other pixel's, and a masked layer (a shadow, an outline) no longer pays for the whole frame.
  for (int y = ys; y != ye; y += q) {
    int cur = 0;
    if (searched(S, xs, y)) draw(xs, y, cand[cur]);
    for (int x = xs; x != xe; x += q) {
      const int next_x = x + q;
      if (next_x != xe && searched(S, next_x, y)) draw(next_x, y, cand[cur ^ 1]);
      if (searched(S, x, y)) {
        int32_t* n = L.nnf->at(x, y);
        const PixelRefs px{x,
                           y,
                           n,
                           L.err->at(x, y),
                           L.tgt->at(x + L.border - r, y + L.border - r),
                           occupancy_weight(L, x, y)};
        PixelMove mv{n[0], n[1], n[0], n[1]};
        float cur_occ = occupancy(S, band, n[0], n[1], mv) * px.occ_weight;
        // Propagation from the neighbours already visited in this sweep's direction.
        const int nx = x - q;
        if (nx >= 0 && nx < L.tw && is_active(L, nx, y)) {
          const int32_t* m = L.nnf->at(nx, y);
          const int cx = m[0] + q;
          if (cx >= lo_x && cx <= hi_x) {
            try_candidate(S, band, px, cx, m[1], mv, cur_occ);
            if (kcoh) try_set(S, band, px, cx, m[1], mv, cur_occ);
          }
        }
        const int ny = y - q;
        if (ny >= 0 && ny < L.th && is_active(L, x, ny)) {
          // Across the band edge the neighbouring band is not being swept in this round.
          const int32_t* m = L.nnf->at(x, ny);
          const int cy = m[1] + q;
          if (cy >= lo_y && cy <= hi_y) {
            try_candidate(S, band, px, m[0], cy, mv, cur_occ);
            if (kcoh) try_set(S, band, px, m[0], cy, mv, cur_occ);
          }
        }
        for (int k = 0; k < num_radii; ++k)
          try_candidate(S, band, px, cand[cur][k][0], cand[cur][k][1], mv, cur_occ);
        if (mv.to_x != mv.from_x || mv.to_y != mv.from_y) {
          const int p = 2 * r + 1;
          add_triangle<-1>(band.delta, L.sw, L.sh, mv.from_x, mv.from_y, p, S.triangle);
          add_triangle<+1>(band.delta, L.sw, L.sh, mv.to_x, mv.to_y, p, S.triangle);
          mark_dirty(band, L.sw, L.sh, mv.from_x, mv.from_y, p);
          mark_dirty(band, L.sw, L.sh, mv.to_x, mv.to_y, p);
        }
      }
      cur ^= 1;
    }
  }
}

}  // namespace

void occupancy_window_sums(const PatchMatchLevel& L, int p, std::vector<int32_t>& sums,
                           std::vector<int32_t>& scratch) {
  // Histogram of patch centres, then a separable triangle filter (p - |d|, |d| < p).
  const std::size_t n = std::size_t(L.sw) * L.sh;
  sums.assign(n, 0);
  scratch.resize(n);
  for (int y = 0; y < L.th; ++y)
    for (int x = 0; x < L.tw; ++x)
      if (is_active(L, x, y)) {
        const int32_t* m = L.nnf->at(x, y);
        sums[std::size_t(m[1]) * L.sw + m[0]] += 1;
      }
  // The triangle (p - |d|, |d| < p) is a box of p taps convolved with itself: a running box
  // sum over the positions up to r beyond the image too (pixels outside count 0), then a running
  // box sum of that. Integer sums: the same as the triangle's taps added one by one.
  const int r = p / 2;
  // Rows: once[i + r] = the box at i in [-r, n + r); out[i] = the box of `once` at i in [0, n).
  parallel_rows(L.sh, 64, [&](int y0, int y1) {
    const int n = L.sw;
    std::vector<int32_t> once(std::size_t(n) + 2 * std::size_t(r));
    for (int y = y0; y < y1; ++y) {
      const int32_t* in = sums.data() + std::size_t(y) * n;
      int32_t* out = scratch.data() + std::size_t(y) * n;
      int32_t s = 0;  // the box at i, less in[i + r]
      for (int i = -r; i < n + r; ++i) {
        if (i + r < n) s += in[i + r];
        once[std::size_t(i + r)] = s;
        if (i - r >= 0) s -= in[i - r];
      }
      s = 0;
      for (int k = 0; k < 2 * r; ++k) s += once[std::size_t(k)];
      for (int i = 0; i < n; ++i) {
        s += once[std::size_t(i + 2 * r)];
        out[i] = s;
        s -= once[std::size_t(i)];
      }
    }
  });
  // Columns, the same row by row over a block of columns at a time.
  constexpr int kBlock = 256;
  const int blocks = (L.sw + kBlock - 1) / kBlock;
  parallel_for(blocks, 1, [&](int64_t b0, int64_t b1) {
    const int n = L.sh;
    std::vector<int32_t> once((std::size_t(n) + 2 * std::size_t(r)) * kBlock), s(kBlock);
    for (int64_t b = b0; b < b1; ++b) {
      const int x0 = int(b) * kBlock, nb = std::min(kBlock, L.sw - x0);
      const auto in = [&](int y) { return scratch.data() + std::size_t(y) * L.sw + x0; };
      const auto row = [&](int i) { return once.data() + std::size_t(i + r) * kBlock; };
      std::fill(s.begin(), s.end(), 0);
      for (int i = -r; i < n + r; ++i) {
        if (i + r < n)
          for (int k = 0; k < nb; ++k) s[k] += in(i + r)[k];
        std::copy(s.begin(), s.begin() + nb, row(i));
        if (i - r >= 0)
          for (int k = 0; k < nb; ++k) s[k] -= in(i - r)[k];
      }
      std::fill(s.begin(), s.end(), 0);
      for (int i = -r; i < r; ++i)
        for (int k = 0; k < nb; ++k) s[k] += row(i)[k];
      for (int y = 0; y < n; ++y) {
        int32_t* out = sums.data() + std::size_t(y) * L.sw + x0;
        for (int k = 0; k < nb; ++k) {
          s[k] += row(y + r)[k];
          out[k] = s[k];
          s[k] -= row(y - r)[k];
        }
      }
    }
  });
}

void compute_errors(const PatchMatchLevel& L, const PatchMatchConfig& C) {
  CHECK_EQ(L.src->channels() % 2, 0);  // the kernels read whole int16 pairs
  const int r = C.patch_size / 2;
  const int row_elems = C.patch_size * L.src->channels();
  parallel_rows(L.th, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < L.tw; ++x) {
        if (!is_active(L, x, y)) {
          (*L.err)(x, y) = 0.0f;
          continue;
        }
        const int32_t* m = L.nnf->at(x, y);
        const int64_t ssd =
            patch_distance(L, C, x, y, L.tgt->at(x + L.border - r, y + L.border - r),
                           L.src->at(m[0] - r, m[1] - r), row_elems, C.patch_size,
                           std::numeric_limits<int64_t>::max());
        (*L.err)(x, y) = float(double(ssd) * C.err_scale);
      }
  });
}

void run_patch_match(const PatchMatchLevel& L, const PatchMatchConfig& C) {
  CHECK(C.ssd != nullptr);
  CHECK_EQ(C.patch_size % 2, 1);
  CHECK_EQ(L.src->channels() % 2, 0);
  if (C.coherence) CHECK(C.coherence->width == L.sw && C.coherence->height == L.sh);
  const int p = C.patch_size;
  int64_t active_count = 0;
  for (int y = 0; y < L.th; ++y)
    for (int x = 0; x < L.tw; ++x) active_count += is_active(L, x, y) ? 1 : 0;
  if (active_count == 0) return;
  const double omega_best = double(active_count) / (double(L.sw) * L.sh) * p * p;
  const float occ_scale =
      C.uniformity > 0.0f ? float(C.uniformity / (double(p) * p * omega_best)) : 0.0f;

  const int dirty_stride = (L.sw >> kDirtyShift) + 1;
  // Without a uniformity term no window sum is read and no delta written: none is allocated.
  DeltaPool pool(occ_scale > 0.0f ? std::size_t(L.sw) * L.sh : 0,
                 std::size_t(dirty_stride) * ((L.sh >> kDirtyShift) + 1));
  const int band = band_rows(L.th);
  const int bands = (L.th + band - 1) / band;
  static_assert(kRounds >= 2);
  const int rounds = std::min(bands, kRounds);
  // The window sums are computed once; each round's deltas are folded into them afterwards.
  std::vector<int32_t> occ;
  if (occ_scale > 0.0f) {
    // The scratch goes before the sweeps' deltas are allocated: it is not needed past here.
    std::vector<int32_t> scratch;
    occupancy_window_sums(L, p, occ, scratch);
  }
  const std::vector<int32_t> triangle = triangle_table(p);
  const Sweep sweep{L,
                    C,
                    occ.data(),
                    occ_scale,
                    p / 2,
                    L.src->stride(),
                    p * L.src->channels(),
                    1.0 / C.err_scale,
                    triangle.data()};
  const int block_rows = (L.sh + (1 << kDirtyShift) - 1) >> kDirtyShift;
  for (int iter = 0; iter < C.iterations; ++iter) {
    if (C.before_sweep) (*C.before_sweep)();
    for (int round = 0; round < rounds; ++round) {
      const int in_round = (bands - round + rounds - 1) / rounds;
      std::vector<DeltaBuffers> used(in_round);
      parallel_for(in_round, 1, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
          const int b = round + int(i) * rounds;
          used[i] = pool.take();
          Band bd{used[i].delta.data(), used[i].dirty.data(), dirty_stride};
          sweep_band(sweep, bd, b * band, std::min(L.th, (b + 1) * band), iter);
        }
      });
      parallel_for(block_rows, 8, [&](int64_t by0, int64_t by1) {
        for (auto& buf : used)
          fold_band(buf, dirty_stride, occ_scale > 0.0f ? occ.data() : nullptr, L.sw, L.sh,
                    int(by0), int(by1));
      });
      for (auto& buf : used) pool.give(std::move(buf));  // zeroed by the fold
    }
  }
}

// ---- starting fields ----

Image<int32_t> upscale_nnf(const Image<int32_t>& coarse, int tw, int th, int sw, int sh, int r) {
  Image<int32_t> out(tw, th, 2);
  parallel_rows(th, 64, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < tw; ++x) {
        const int32_t* m =
            coarse.at(std::min(x / 2, coarse.width() - 1), std::min(y / 2, coarse.height() - 1));
        out(x, y, 0) = std::clamp(2 * m[0] + (x & 1), r, sw - r - 1);
        out(x, y, 1) = std::clamp(2 * m[1] + (y & 1), r, sh - r - 1);
      }
  });
  return out;
}

Image<int32_t> identity_nnf(int tw, int th, int sw, int sh, int r) {
  Image<int32_t> out(tw, th, 2);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) {
      out(x, y, 0) = std::clamp(int((int64_t(x) * sw) / tw), r, sw - 1 - r);
      out(x, y, 1) = std::clamp(int((int64_t(y) * sh) / th), r, sh - 1 - r);
    }
  return out;
}

void random_entry(int x, int y, int sw, int sh, int r, uint64_t seed, int32_t* out) {
  CounterRng rng(hash_key(seed, 0x1417, uint64_t(y) * 65536u + uint64_t(x)));
  out[0] = r + int(rng.uniform(uint32_t(sw - 2 * r)));
  out[1] = r + int(rng.uniform(uint32_t(sh - 2 * r)));
}

Image<int32_t> random_nnf(int tw, int th, int sw, int sh, int r, uint64_t seed) {
  Image<int32_t> out(tw, th, 2);
  for (int y = 0; y < th; ++y)
    for (int x = 0; x < tw; ++x) random_entry(x, y, sw, sh, r, seed, out.at(x, y));
  return out;
}

}  // namespace emaki::synth
