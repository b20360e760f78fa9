// PNG read through libpng directly (png_io.cpp) and written by emaki with zlib, in parallel strips
// (png_write.cpp): the format most guides and exemplars come in. Kept apart from
// OpenImageIO because Debian's OpenImageIO pulls in ~120 MB of libraries (OpenVDB, GDAL, ...)
// at load time, more than the whole synthesis of a 1200x912 frame needs; OpenImageIO is loaded
// only when another format is read or written (see image_io.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "io/image_io.h"

namespace emaki::io::detail {

// Closes a FILE held by a unique_ptr (the reader's and the writer's files).
struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};

// 8/16-bit gray, gray+alpha, RGB, RGBA (palette and low bit depths are expanded to 8-bit).
// The size in the header is checked against the pixel budget (core/limits.h) before any pixel
// memory is allocated. Errors throw emaki::Error naming `path` (or `name`).
AnyImage read_png(const std::string& path);
// The same from a file the caller opened (read from its current position, left open); `name` is
// the error subject.
AnyImage read_png(std::FILE* file, const std::string& name);
// The same from bytes in memory; `name` is the error subject.
AnyImage read_png_memory(const void* data, std::size_t size, const std::string& name);
// Only the header: channel names (R, G, B, A / Y, A) with an empty image.
AnyImage read_png_header(const std::string& path);
// Writes 8- or 16-bit PNG with 1-4 channels, values clamped to [0, 1]. `path` is written as is
// (the caller makes it atomic). Returns the file's size in bytes.
uint64_t write_png(const std::string& path, ImageView<const float> image, bool sixteen_bit,
                   const std::string& error_subject);
// The same into an open file, which it closes (the caller created it, e.g. exclusively).
uint64_t write_png(std::FILE* file, ImageView<const float> image, bool sixteen_bit,
                   const std::string& error_subject);
// Throws emaki::Error(subject) unless the file at `path` is a whole PNG as write_png makes one:
// `size` bytes (when not 0), a header that reads, and the IEND chunk as its last 12 bytes.
void check_png_complete(const std::string& path, uint64_t size, const std::string& subject);

}  // namespace emaki::io::detail
