// Image<T>: an owning, interleaved image with any channel count whose rows are aligned and
// padded to 64 bytes, so SIMD row loads are aligned and threads writing different rows never
// share a cache line (after highway's contrib/image). ImageView<T>: the non-owning (pointer,
// size, stride) window that algorithms take (after OpenImageIO). Images are move-only; copies
// are explicit (clone()).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>

#include "core/check.h"

namespace emaki {

inline constexpr std::size_t kRowAlign = 64;

namespace detail {
// Called with each new image's block before its first touch, when set. How the memory is
// mapped is a front end's choice (core/performance.h sets it), not the image type's. Inline, so
// that every library holding images (also the dlopen'ed OpenImageIO module, which is handed
// the front end's hook when it loads) has one.
using ImageBlockHook = void (*)(void* block, std::size_t bytes);
inline std::atomic<ImageBlockHook> image_block_hook{nullptr};
}  // namespace detail

template <typename T>
struct ImageView {
  T* data = nullptr;
  int width = 0;
  int height = 0;
  int channels = 0;
  std::ptrdiff_t stride = 0;  // elements between the starts of consecutive rows

  T* row(int y) const { return data + y * stride; }
  T* at(int x, int y) const { return data + y * stride + std::ptrdiff_t(x) * channels; }
  T& operator()(int x, int y, int c = 0) const { return at(x, y)[c]; }
  bool empty() const { return data == nullptr || width <= 0 || height <= 0; }
  operator ImageView<const T>() const requires(!std::is_const_v<T>) {
    return {data, width, height, channels, stride};
  }
};

template <typename T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels) { reset(width, height, channels); }
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;
  Image(Image&& o) noexcept { *this = std::move(o); }
  Image& operator=(Image&& o) noexcept {
    mem_ = std::move(o.mem_);
    width_ = std::exchange(o.width_, 0);
    height_ = std::exchange(o.height_, 0);
    channels_ = std::exchange(o.channels_, 0);
    stride_ = std::exchange(o.stride_, 0);
    return *this;
  }

  // Allocates zero-filled storage (zero so that row padding is deterministic too). Throws
  // std::bad_alloc when the memory is not there: sizes can come from a file within a raised
  // pixel budget, and the reader turns that into an error naming the file, not an abort. The
  // image is left unchanged then.
  void reset(int width, int height, int channels) {
    CHECK_GE(width, 0);
    CHECK_GE(height, 0);
    CHECK_GT(channels, 0);
    const std::size_t row_bytes = std::size_t(width) * channels * sizeof(T);
    const std::size_t padded = (row_bytes + kRowAlign - 1) / kRowAlign * kRowAlign;
    const std::size_t bytes = std::max<std::size_t>(padded * height, kRowAlign);
    // calloc, aligned by hand, rather than aligned_alloc and memset: glibc's calloc does not
    // write memory fresh from the kernel (zero already), and the memset was a pass over every
    // new image's pages, faulting them in before their writer did.
    void* block = std::calloc(bytes + kRowAlign, 1);
    if (block == nullptr) throw std::bad_alloc();
    const std::uintptr_t at =
        (reinterpret_cast<std::uintptr_t>(block) + kRowAlign - 1) & ~std::uintptr_t(kRowAlign - 1);
    T* mem = reinterpret_cast<T*>(at);
    mem_ = std::unique_ptr<T, Free>(mem, Free{nullptr, block, 0});
    if (const detail::ImageBlockHook hook =
            detail::image_block_hook.load(std::memory_order_relaxed))
      hook(mem, bytes);
    width_ = width;
    height_ = height;
    channels_ = channels;
    stride_ = std::ptrdiff_t(padded / sizeof(T));
  }

  // An image over a block the caller made (rows `stride` elements apart, the first at `data`,
  // aligned to kRowAlign), handed back as release(block, bytes) when the image goes: a file
  // mapped into memory is so read without a copy into fresh pages (store/reference_cache.cpp).
  static Image adopt(T* data, int width, int height, int channels, std::ptrdiff_t stride,
                     void* block, std::size_t bytes, void (*release)(void*, std::size_t)) {
    CHECK_GE(stride, std::ptrdiff_t(width) * channels);
    Image out;
    out.mem_ = std::unique_ptr<T, Free>(data, Free{release, block, bytes});
    out.width_ = width;
    out.height_ = height;
    out.channels_ = channels;
    out.stride_ = stride;
    return out;
  }

  Image clone() const {
    Image out(width_, height_, channels_);
    if (height_ > 0) std::memcpy(out.mem_.get(), mem_.get(), bytes());
    return out;
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  std::ptrdiff_t stride() const { return stride_; }
  std::size_t bytes() const { return std::size_t(stride_) * height_ * sizeof(T); }
  bool empty() const { return width_ == 0 || height_ == 0; }

  T* row(int y) { return mem_.get() + y * stride_; }
  const T* row(int y) const { return mem_.get() + y * stride_; }
  T* at(int x, int y) { return row(y) + std::ptrdiff_t(x) * channels_; }
  const T* at(int x, int y) const { return row(y) + std::ptrdiff_t(x) * channels_; }
  T& operator()(int x, int y, int c = 0) { return at(x, y)[c]; }
  const T& operator()(int x, int y, int c = 0) const { return at(x, y)[c]; }

  ImageView<T> view() { return {mem_.get(), width_, height_, channels_, stride_}; }
  ImageView<const T> view() const { return {mem_.get(), width_, height_, channels_, stride_}; }
  ImageView<const T> cview() const { return view(); }

  void fill(T v) {
    for (int y = 0; y < height_; ++y)
      std::fill(row(y), row(y) + std::size_t(width_) * channels_, v);
  }

 private:
  // std::free of the block calloc gave (the data starts inside it), unless it was adopted.
  struct Free {
    void (*release)(void*, std::size_t) = nullptr;
    void* block = nullptr;
    std::size_t bytes = 0;
    void operator()(T*) const {
      if (release)
        release(block, bytes);
      else
        std::free(block);
    }
  };
  std::unique_ptr<T, Free> mem_;
  int width_ = 0, height_ = 0, channels_ = 0;
  std::ptrdiff_t stride_ = 0;
};

using ImageF = Image<float>;

// A value as an 8- or 16-bit sample: clamped to [0, 1], then rounded to nearest. PNG files and
// the Python module's integer results are made by these, so they agree to the bit.
inline uint8_t to_u8(float v) {
  return uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}
inline uint16_t to_u16(float v) {
  return uint16_t(std::clamp(v, 0.0f, 1.0f) * 65535.0f + 0.5f);
}

// The inverse direction: an 8- or 16-bit sample as a value in [0, 1] (floats as they are). Every
// reader normalises so, so that "opaque" (1) means the same whichever front end loaded an image.
template <typename T>
float normalised(T v) {
  if constexpr (std::is_same_v<T, uint8_t>)
    return v * (1.0f / 255.0f);
  else if constexpr (std::is_same_v<T, uint16_t>)
    return v * (1.0f / 65535.0f);
  else
    return v;
}

}  // namespace emaki
