#include "temporal/coherent_field.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "core/parallel.h"

namespace emaki::temporal {
namespace {

// An offset (patch centre minus position) as one key. No pixel with a patch has kNone: its x
// offset would be INT32_MIN, below -x.
constexpr int64_t kNone = INT64_MIN;

int64_t offset_key(ImageView<const int32_t> f, int x, int y) {
  if (f(x, y, 0) < 0) return kNone;
  return int64_t(uint64_t(uint32_t(f(x, y, 0) - x)) << 32 | uint32_t(f(x, y, 1) - y));
}

// How many pixels of a sliding window have each offset in it: the offsets present, each with its
// count, and an open-addressing table from offset to its place among them (linear probing; a
// removed slot closes its probe chain by shifting the later entries back).
class WindowCounts {
 public:
  explicit WindowCounts(int most) {
    std::size_t capacity = 64;
    while (capacity < 2 * std::size_t(most)) capacity *= 2;
    mask_ = capacity - 1;
    slots_.assign(capacity, -1);
    keys_.reserve(std::size_t(most));
    counts_.reserve(std::size_t(most));
  }

  void clear() {
    std::fill(slots_.begin(), slots_.end(), -1);
    keys_.clear();
    counts_.clear();
    total_ = 0;
  }
  void add(int64_t key) {
    if (key == kNone) return;
    ++total_;
    const std::size_t s = find(key);
    if (slots_[s] >= 0) {
      ++counts_[std::size_t(slots_[s])];
      return;
    }
    slots_[s] = int32_t(keys_.size());
    keys_.push_back(key);
    counts_.push_back(1);
  }
  void remove(int64_t key) {
    if (key == kNone) return;
    --total_;
    std::size_t s = find(key);
    const auto i = std::size_t(slots_[s]);
    if (--counts_[i] > 0) return;
    // Out of the list (the last one takes its place), then out of the table.
    if (i + 1 != keys_.size()) {
      slots_[find(keys_.back())] = int32_t(i);
      keys_[i] = keys_.back();
      counts_[i] = counts_.back();
    }
    keys_.pop_back();
    counts_.pop_back();
    slots_[s] = -1;
    for (std::size_t j = (s + 1) & mask_; slots_[j] >= 0; j = (j + 1) & mask_) {
      const std::size_t home = slot_of(keys_[std::size_t(slots_[j])]);
      // The entry at j may move back to s when s lies on its probe path, from home to j.
      if (((j - home) & mask_) >= ((j - s) & mask_)) {
        slots_[s] = slots_[j];
        slots_[j] = -1;
        s = j;
      }
    }
  }

  int total() const { return total_; }
  int count(int64_t key) const {
    const std::size_t s = find(key);
    return slots_[s] >= 0 ? counts_[std::size_t(slots_[s])] : 0;
  }
  const std::vector<int64_t>& keys() const { return keys_; }
  const std::vector<int>& counts() const { return counts_; }

 private:
  std::size_t slot_of(int64_t key) const {
    return std::size_t((uint64_t(key) * 0x9E3779B97F4A7C15ull) >> 32) & mask_;
  }
  // The slot holding `key`, or the empty slot where it would go.
  std::size_t find(int64_t key) const {
    std::size_t s = slot_of(key);
    while (slots_[s] >= 0 && keys_[std::size_t(slots_[s])] != key) s = (s + 1) & mask_;
    return s;
  }

  std::size_t mask_ = 0;
  std::vector<int32_t> slots_;  // place in keys_ and counts_, -1: empty
  std::vector<int64_t> keys_;
  std::vector<int> counts_;
  int total_ = 0;
};

}  // namespace

Image<int32_t> coherent_field(ImageView<const int32_t> field, int radius) {
  const int w = field.width, h = field.height;
  Image<int32_t> out(w, h, 2);
  for (int y = 0; y < h; ++y)
    std::memcpy(out.row(y), field.row(y), sizeof(int32_t) * 2 * std::size_t(w));
  if (radius <= 0) return out;
  std::vector<int64_t> keys(std::size_t(w) * std::size_t(h));
  parallel_rows(h, 64, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x)
        keys[std::size_t(y) * std::size_t(w) + std::size_t(x)] = offset_key(field, x, y);
  });
  const int r = radius, side = 2 * r + 1;
  const auto key_at = [&](int x, int y) {
    return keys[std::size_t(y) * std::size_t(w) + std::size_t(x)];
  };
  parallel_rows(h, 16, [&](int band0, int band1) {
    WindowCounts window(side * side);
    for (int y = band0; y < band1; ++y) {
      const int y0 = std::max(0, y - r), y1 = std::min(h - 1, y + r);
      const auto add_column = [&](int c) {
        for (int yy = y0; yy <= y1; ++yy) window.add(key_at(c, yy));
      };
      const auto remove_column = [&](int c) {
        for (int yy = y0; yy <= y1; ++yy) window.remove(key_at(c, yy));
      };
      // When several offsets have the most pixels: the one met first in row order.
      const auto first_with = [&](int count, int x0, int x1) {
        for (int yy = y0; yy <= y1; ++yy)
          for (int xx = x0; xx <= x1; ++xx)
            if (const int64_t k = key_at(xx, yy); k != kNone && window.count(k) == count) return k;
        return kNone;  // not reached: `count` is some offset's
      };
      window.clear();
      for (int c = 0; c <= std::min(w - 1, r); ++c) add_column(c);
      for (int x = 0; x < w; ++x) {
        if (x > 0) {
          if (x - 1 - r >= 0) remove_column(x - 1 - r);
          if (x + r < w) add_column(x + r);
        }
        const int64_t own = key_at(x, y);
        if (own == kNone) continue;
        // When the pixels with the own offset are at least half of those with a patch, no other
        // offset can have more of them.
        const int own_count = window.count(own);
        if (2 * own_count >= window.total()) continue;
        int best = own_count, tied = 0;
        int64_t mode = own;
        for (std::size_t i = 0; i < window.keys().size(); ++i) {
          const int n = window.counts()[i];
          if (n > best) {
            best = n, mode = window.keys()[i], tied = 1;
          } else if (n == best && tied > 0) {
            ++tied;
          }
        }
        if (tied > 1) mode = first_with(best, std::max(0, x - r), std::min(w - 1, x + r));
        if (mode == own) continue;
        out(x, y, 0) = x + int32_t(uint32_t(uint64_t(mode) >> 32));
        out(x, y, 1) = y + int32_t(uint32_t(uint64_t(mode)));
      }
    }
  });
  return out;
}

}  // namespace emaki::temporal
