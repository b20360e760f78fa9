// Limits on what a file or an option may ask emaki to allocate or loop over, and checked
// arithmetic for every size, count, offset and frame number that comes from outside.
// Files come from other people and run unattended on a farm: a header that claims
// 100000x100000 pixels must fail from the header, before any allocation.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>

#include "core/error.h"

namespace emaki {

// Default pixel budget per image: 2^28 pixels (16384 x 16384), 4 GiB as float RGBA.
inline constexpr int64_t kDefaultMaxPixels = int64_t(1) << 28;

namespace detail {
inline std::atomic<int64_t>& max_pixels_slot() {
  static std::atomic<int64_t> v{kDefaultMaxPixels};
  return v;
}
inline std::atomic<bool>& max_pixels_pinned_slot() {
  static std::atomic<bool> v{false};
  return v;
}
// This thread's ScopedMaxPixels budget; 0: none lives.
inline thread_local int64_t t_max_pixels = 0;
}  // namespace detail

// The pixel budget of the work on this thread: the innermost ScopedMaxPixels's, else the
// process's (`--max-pixels` on the CLI, else kDefaultMaxPixels).
inline int64_t max_pixels() {
  const int64_t scoped = detail::t_max_pixels;
  return scoped > 0 ? scoped : detail::max_pixels_slot().load(std::memory_order_relaxed);
}
// This thread's ScopedMaxPixels budget, 0 when none lives (parallel_for hands it to workers).
inline int64_t scoped_max_pixels() {
  return detail::t_max_pixels;
}
// Sets the process's budget and pins it: the command line's --max-pixels, set before any work,
// wins over every shot file's limits.max_pixels.
inline void set_max_pixels(int64_t n) {
  detail::max_pixels_slot().store(n, std::memory_order_relaxed);
  detail::max_pixels_pinned_slot().store(true, std::memory_order_relaxed);
}

// While it lives, max_pixels() on the constructing thread (and in the parallel_for calls it
// makes) is `n` (0: unchanged). A shot's `limits.max_pixels` is applied this way for the
// duration of that shot's parsing and work, so it never reaches another shot or another call.
class ScopedMaxPixels {
 public:
  explicit ScopedMaxPixels(int64_t n) : previous_(detail::t_max_pixels) {
    if (n > 0) detail::t_max_pixels = n;
  }
  ~ScopedMaxPixels() { detail::t_max_pixels = previous_; }
  ScopedMaxPixels(const ScopedMaxPixels&) = delete;
  ScopedMaxPixels& operator=(const ScopedMaxPixels&) = delete;

 private:
  int64_t previous_;
};

// The budget a shot's work runs under: the pinned --max-pixels, else the shot file's
// `limits.max_pixels` (`from_file`, 0 when the file sets none), else the process's.
inline int64_t shot_max_pixels(int64_t from_file) {
  if (detail::max_pixels_pinned_slot().load(std::memory_order_relaxed) || from_file <= 0)
    return detail::max_pixels_slot().load(std::memory_order_relaxed);
  return from_file;
}

// Frame numbers and counts from a shot file or an option (documented in docs/shot_file.md):
// frames lie in [0, kMaxFrame] and a range holds at most kMaxFrameCount frames, so frame
// arithmetic (f - 1, f + count, first + last) never overflows an int and no loop over a range
// runs for hours before its first progress line.
inline constexpr int kMaxFrame = 10'000'000;
inline constexpr int kMaxFrameCount = 1'000'000;

// Overflow-checked arithmetic: nullopt when the exact result does not fit in T.
template <typename T>
std::optional<T> checked_mul(T a, T b) {
  T r;
  if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
  return r;
}
template <typename T>
std::optional<T> checked_add(T a, T b) {
  T r;
  if (__builtin_add_overflow(a, b, &r)) return std::nullopt;
  return r;
}

// The length of `value`'s longest prefix of at most `cap` bytes that does not split a UTF-8
// character: error lines must stay valid UTF-8 (Python's str, JSON).
inline std::size_t utf8_prefix(std::string_view value, std::size_t cap) {
  if (value.size() <= cap) return value.size();
  std::size_t n = cap;
  for (int back = 0; back < 3 && n > 0 && (static_cast<unsigned char>(value[n]) & 0xC0) == 0x80;
       ++back)
    --n;
  return n;
}

// A user value shown in an error line, cut to `cap` bytes at a character boundary: a 100 MB clip
// name must not be echoed whole. Control characters are shown as '?'.
inline std::string echo(std::string_view value, std::size_t cap = 80) {
  std::string out;
  const std::size_t n = utf8_prefix(value, cap);
  out.reserve(n + 16);
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(value[i]);
    out += (c < 0x20 || c == 0x7f) ? '?' : char(c);
  }
  if (value.size() > cap) out += "... (" + std::to_string(value.size()) + " bytes)";
  return out;
}

// A file or folder path in an error line: whole up to 400 bytes (studio paths run past 80 and
// the file name at the end is what the user needs); a longer one keeps its first 100 and last
// 280 bytes (fewer where a character would be split) around "...(N bytes)...", so the line stays
// short and still ends in the file name.
inline std::string echo_path(std::string_view path) {
  constexpr std::size_t kWhole = 400, kHead = 100, kTail = 280;
  if (path.size() <= kWhole) return echo(path, kWhole);
  std::size_t tail = path.size() - kTail;
  for (int on = 0; on < 3 && (static_cast<unsigned char>(path[tail]) & 0xC0) == 0x80; ++on) ++tail;
  return echo(path.substr(0, utf8_prefix(path, kHead)), kHead) + "...(" +
         std::to_string(path.size()) + " bytes)..." + echo(path.substr(tail), kTail);
}

// Throws Error(subject) when width x height is not a positive size within the pixel budget.
// Call it with the sizes a header claims, before allocating anything.
inline void check_pixel_budget(const std::string& subject, int64_t width, int64_t height) {
  if (width <= 0 || height <= 0)
    throw Error(subject, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " is not positive");
  const auto n = checked_mul<int64_t>(width, height);
  if (!n || *n > max_pixels())
    throw Error(subject, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " exceeds the pixel budget of " + std::to_string(max_pixels()) +
                             " pixels (raise it with --max-pixels or limits.max_pixels)");
  if (width > std::numeric_limits<int>::max() / 4 || height > std::numeric_limits<int>::max() / 4)
    throw Error(subject, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                             " is too large");
}

}  // namespace emaki
