// What an image reader checks between a file's header and its first allocation. Shared by the
// PNG reader (png_io.cpp) and the OpenImageIO plugin (oiio_backend.cpp).
#pragma once

#include <cstdint>
#include <new>
#include <optional>
#include <string>

#include "core/error.h"
#include "core/image.h"
#include "core/limits.h"

namespace emaki::io::detail {

// More channels than this in one image (or one EXR part) is taken as a corrupt or hostile
// header: emaki's guides and styles have 1 to 4, multilayer render passes a few dozen.
inline constexpr int kMaxChannels = 64;
// More parts (EXR subimages) than this is taken as a corrupt or hostile file; named channels
// are searched in every part, so the count also bounds that search.
inline constexpr int kMaxParts = 256;

// Throws Error(subject) unless an Image<T> of width x height x channels, as a header claims it,
// fits the pixel budget and the memory the budget stands for. The pixel count alone is not
// enough: Image pads each row to kRowAlign bytes, so a 1 x 2^28 image would take 16 GiB while
// counting as 2^28 pixels. The memory allowed is the budget as float RGBA (16 bytes a pixel),
// the figure core/limits.h documents.
template <typename T>
void check_image_alloc(const std::string& subject, int64_t width, int64_t height,
                       int64_t channels) {
  check_pixel_budget(subject, width, height);
  if (channels < 1 || channels > kMaxChannels)
    throw Error(subject, std::to_string(channels) + " channels (emaki reads 1 to " +
                             std::to_string(kMaxChannels) + ")");
  std::optional<int64_t> row = checked_mul<int64_t>(width, channels);
  if (row) row = checked_mul<int64_t>(*row, int64_t(sizeof(T)));
  if (row) row = checked_add<int64_t>(*row, int64_t(kRowAlign) - 1);
  if (row) *row = *row / int64_t(kRowAlign) * int64_t(kRowAlign);
  const std::optional<int64_t> bytes = row ? checked_mul<int64_t>(*row, height) : std::nullopt;
  const std::optional<int64_t> allowed = checked_mul<int64_t>(max_pixels(), 16);
  if (!bytes || (allowed && *bytes > *allowed))
    throw Error(subject, "a " + std::to_string(width) + "x" + std::to_string(height) + "x" +
                             std::to_string(channels) +
                             " image needs more memory than the pixel budget of " +
                             std::to_string(max_pixels()) +
                             " pixels allows (raise it with --max-pixels or limits.max_pixels)");
}

// Allocates the image a checked header asked for; running out of memory (a budget raised past
// what the machine or `ulimit -v` gives) is an error naming the file, not an abort.
template <typename T>
Image<T> allocate_image(const std::string& subject, int width, int height, int channels) {
  try {
    return Image<T>(width, height, channels);
  } catch (const std::bad_alloc&) {
    throw Error(subject, "not enough memory for a " + std::to_string(width) + "x" +
                             std::to_string(height) + "x" + std::to_string(channels) + " image");
  }
}

}  // namespace emaki::io::detail
