#include "synth/exemplar_index.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/check.h"
#include "core/error.h"
#include "core/fnv.h"
#include "core/parallel.h"
#include "core/rng.h"

namespace emaki::synth {

namespace {

// ---------------------------------------------------------------------------------------------
// Building the sets

constexpr int64_t kNoDistance = std::numeric_limits<int64_t>::max();

// Each centre's k best as (distance, centre) pairs, nearest first, unused slots at kNoDistance.
struct Lists {
  int k = 0;
  std::vector<int64_t> dist;
  std::vector<int32_t> cand;
  int64_t* d(std::size_t i) { return dist.data() + i * k; }
  int32_t* c(std::size_t i) { return cand.data() + i * k; }
  const int32_t* c(std::size_t i) const { return cand.data() + i * k; }
};

struct Builder {
  const Image<int16_t>& src;
  int p, r, k, ex, sw, sh, row_elems;
  PatchSsdFn ssd;
  uint64_t seed;

  bool valid(int x, int y) const { return x >= r && x < sw - r && y >= r && y < sh - r; }

  // Offers centre (cx, cy) to the list of centre (x, y).
  void offer(int64_t* d, int32_t* c, int x, int y, int cx, int cy) const {
    if (!valid(cx, cy) || (std::abs(cx - x) <= ex && std::abs(cy - y) <= ex)) return;
    const int32_t id = cy * sw + cx;
    for (int i = 0; i < k; ++i)
      if (c[i] == id) return;
    const int64_t bound = d[k - 1];
    const int64_t v = ssd(src.at(x - r, y - r), src.stride(), src.at(cx - r, cy - r), src.stride(),
                          row_elems, p, bound);
    if (v >= bound) return;
    int i = k - 1;
    for (; i > 0 && d[i - 1] > v; --i) d[i] = d[i - 1], c[i] = c[i - 1];
    d[i] = v, c[i] = id;
  }

  // Starting lists: the coarser level's sets doubled (when given) and k random draws.
  void start(Lists& L, const CoherenceSets* coarser) const {
    parallel_rows(sh, 16, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < sw; ++x) {
          const std::size_t i = std::size_t(y) * sw + x;
          int64_t* d = L.d(i);
          int32_t* c = L.c(i);
          std::fill(d, d + k, kNoDistance);
          std::fill(c, c + k, -1);
          if (!valid(x, y)) continue;
          if (coarser != nullptr) {
            const int32_t* set = coarser->at(std::min(x / 2, coarser->width - 1),
                                             std::min(y / 2, coarser->height - 1));
            for (int j = 0; j < coarser->k && set[j] >= 0; ++j)
              offer(d, c, x, y, 2 * (set[j] % coarser->width) + (x & 1),
                    2 * (set[j] / coarser->width) + (y & 1));
          }
          CounterRng rng(hash_key(seed, 0x1de, uint64_t(y) * 65536u + uint64_t(x)));
          for (int j = 0; j < k; ++j)
            offer(d, c, x, y, r + int(rng.uniform(uint32_t(sw - 2 * r))),
                  r + int(rng.uniform(uint32_t(sh - 2 * r))));
        }
    });
  }

  // One sweep over rows [y0, y1): `cur` holds this band's rows as swept so far, `prev` every
  // list as the sweep began (read for the rows of other bands).
  void sweep_band(Lists& cur, const Lists& prev, int y0, int y1, int iter) const {
    const bool forward = iter % 2 == 0;
    const int q = forward ? 1 : -1;
    const int ys = forward ? y0 : y1 - 1, ye = forward ? y1 : y0 - 1;
    const int xs = forward ? 0 : sw - 1, xe = forward ? sw : -1;
    auto list = [&](int x, int y) -> const int32_t* {
      const std::size_t i = std::size_t(y) * sw + x;
      return y >= y0 && y < y1 ? cur.c(i) : prev.c(i);
    };
    for (int y = ys; y != ye; y += q)
      for (int x = xs; x != xe; x += q) {
        if (!valid(x, y)) continue;
        const std::size_t i = std::size_t(y) * sw + x;
        int64_t* d = cur.d(i);
        int32_t* c = cur.c(i);
        // Propagation: the neighbours' sets shifted by the step to this centre.
        if (valid(x - q, y)) {
          const int32_t* n = list(x - q, y);
          for (int j = 0; j < k && n[j] >= 0; ++j) offer(d, c, x, y, n[j] % sw + q, n[j] / sw);
        }
        if (valid(x, y - q)) {
          const int32_t* n = list(x, y - q);
          for (int j = 0; j < k && n[j] >= 0; ++j) offer(d, c, x, y, n[j] % sw, n[j] / sw + q);
        }
        // The nearest one's own set (a patch close to a close patch is likely close).
        if (c[0] >= 0) {
          const int32_t* n = prev.c(std::size_t(c[0]));
          for (int j = 0; j < k && n[j] >= 0; ++j) offer(d, c, x, y, n[j] % sw, n[j] / sw);
        }
        // Random search around the nearest one, at halving radii.
        CounterRng rng(hash_key(seed, uint64_t(iter) + 1, uint64_t(y) * 65536u + uint64_t(x)));
        for (int rad = std::max(sw, sh); rad >= 1; rad /= 2) {
          const int bx = c[0] >= 0 ? c[0] % sw : x, by = c[0] >= 0 ? c[0] / sw : y;
          const int wx0 = std::max(r, bx - rad), wx1 = std::min(sw - r - 1, bx + rad);
          const int wy0 = std::max(r, by - rad), wy1 = std::min(sh - r - 1, by + rad);
          offer(d, c, x, y, wx0 + int(rng.uniform(uint32_t(wx1 - wx0 + 1))),
                wy0 + int(rng.uniform(uint32_t(wy1 - wy0 + 1))));
        }
      }
  }
};

// Bands of the self-match: a height that depends only on the size.
int index_band_rows(int height) {
  return std::max(16, (height + 15) / 16);
}

// ---------------------------------------------------------------------------------------------
// Bytes

constexpr char kMagic[8] = {'E', 'M', 'K', 'I', 'N', 'D', 'E', 'X'};
constexpr uint32_t kVersion = 1;
constexpr int kMaxLevels = 32;
constexpr int kMaxSide = 1 << 16;

void put32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(uint8_t(v >> (8 * i)));
}
void put64(std::vector<uint8_t>& out, uint64_t v) {
  put32(out, uint32_t(v));
  put32(out, uint32_t(v >> 32));
}
uint32_t get32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
uint64_t get64(const uint8_t* p) {
  return uint64_t(get32(p)) | uint64_t(get32(p + 4)) << 32;
}

uint64_t bytes_digest(const uint8_t* p, std::size_t n) {
  uint64_t h = kFnvOffset;
  for (std::size_t i = 0; i < n; ++i) h = fnv1a_add(h, p[i]);
  return h;
}

}  // namespace

CoherenceSets build_coherence_sets(const Image<int16_t>& src, int patch_size, int k,
                                   const CoherenceSets* coarser, PatchSsdFn ssd, uint64_t seed) {
  CHECK(patch_size % 2 == 1);
  CHECK(k >= 1 && k <= kMaxIndexK);
  CHECK_EQ(src.channels() % 2, 0);  // the kernels read whole int16 pairs
  const int sw = src.width(), sh = src.height();
  const Builder b{src,
                  patch_size,
                  patch_size / 2,
                  k,
                  index_exclusion(patch_size),
                  sw,
                  sh,
                  patch_size * src.channels(),
                  ssd,
                  seed};
  const std::size_t n = std::size_t(sw) * sh;
  Lists cur{k, std::vector<int64_t>(n * k), std::vector<int32_t>(n * k)};
  b.start(cur, coarser);
  if (sw > 2 * b.r && sh > 2 * b.r) {
    Lists prev = cur;
    const int band = index_band_rows(sh), bands = (sh + band - 1) / band;
    const int sweeps = coarser != nullptr ? 2 : 4;
    for (int iter = 0; iter < sweeps; ++iter) {
      parallel_for(bands, 1, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i)
          b.sweep_band(cur, prev, int(i) * band, std::min(sh, int(i + 1) * band), iter);
      });
      if (iter + 1 < sweeps) prev.dist = cur.dist, prev.cand = cur.cand;
    }
  }
  CoherenceSets out{sw, sh, k, std::move(cur.cand)};
  return out;
}

uint64_t features_digest(const std::vector<const Image<int16_t>*>& levels) {
  uint64_t h = kFnvOffset;
  for (const Image<int16_t>* im : levels) {
    h = fnv1a_add(fnv1a_add(fnv1a_add(h, uint32_t(im->width())), uint32_t(im->height())),
                  uint32_t(im->channels()));
    const std::size_t row = std::size_t(im->width()) * im->channels();
    for (int y = 0; y < im->height(); ++y) {
      const int16_t* v = im->row(y);
      std::size_t i = 0;
      for (; i + 2 <= row; i += 2)
        h = fnv1a_add(h, uint32_t(uint16_t(v[i])) << 16 | uint16_t(v[i + 1]));
      if (i < row) h = fnv1a_add(h, uint16_t(v[i]));
    }
  }
  return h;
}

std::vector<uint8_t> serialize_index(const ExemplarIndex& index) {
  std::vector<uint8_t> out(kMagic, kMagic + sizeof kMagic);
  put32(out, kVersion);
  put32(out, uint32_t(index.patch_size));
  put32(out, uint32_t(index.k));
  put32(out, uint32_t(index.levels.size()));
  put64(out, index.features_digest);
  for (const CoherenceSets& s : index.levels) {
    CHECK_EQ(s.k, index.k);
    put32(out, uint32_t(s.width));
    put32(out, uint32_t(s.height));
    for (int32_t e : s.entries) put32(out, uint32_t(e));
  }
  put64(out, bytes_digest(out.data(), out.size()));
  return out;
}

ExemplarIndex deserialize_index(const uint8_t* bytes, std::size_t size,
                                const std::string& subject) {
  auto fail = [&](const std::string& what) -> Error {
    return Error(subject, "not a valid exemplar index (" + what + ")");
  };
  constexpr std::size_t kHeader = 32, kTrailer = 8;
  if (size < kHeader + kTrailer) throw fail("too short");
  if (std::memcmp(bytes, kMagic, sizeof kMagic) != 0) throw fail("wrong magic");
  if (get32(bytes + 8) != kVersion)
    throw fail(fmt::format("version {}, expected {}", get32(bytes + 8), kVersion));
  const std::size_t body = size - kTrailer;
  if (get64(bytes + body) != bytes_digest(bytes, body)) throw fail("digest mismatch");
  ExemplarIndex index;
  const uint32_t patch = get32(bytes + 12), k = get32(bytes + 16), levels = get32(bytes + 20);
  if (patch < 3 || patch > 63 || patch % 2 == 0) throw fail("patch size");
  if (k < 1 || k > uint32_t(kMaxIndexK)) throw fail("k");
  if (levels < 1 || levels > uint32_t(kMaxLevels)) throw fail("level count");
  index.patch_size = int(patch), index.k = int(k);
  index.features_digest = get64(bytes + 24);
  std::size_t at = kHeader;
  for (uint32_t l = 0; l < levels; ++l) {
    if (body - at < 8) throw fail("truncated");
    const uint32_t w = get32(bytes + at), h = get32(bytes + at + 4);
    at += 8;
    if (w < 1 || h < 1 || w > uint32_t(kMaxSide) || h > uint32_t(kMaxSide)) throw fail("size");
    const std::size_t n = std::size_t(w) * h * k;
    if ((body - at) / 4 < n) throw fail("truncated");
    CoherenceSets s{int(w), int(h), int(k), std::vector<int32_t>(n)};
    const int64_t centres = int64_t(w) * h;
    for (std::size_t i = 0; i < n; ++i, at += 4) {
      const int32_t e = int32_t(get32(bytes + at));
      if (e < -1 || e >= centres) throw fail("entry out of range");
      s.entries[i] = e;
    }
    index.levels.push_back(std::move(s));
  }
  if (at != body) throw fail("bytes left over");
  return index;
}

}  // namespace emaki::synth
