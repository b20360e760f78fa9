// PNG through libpng directly: the format most guides and exemplars come in. Kept apart from
// OpenImageIO because Debian's OpenImageIO pulls in ~120 MB of libraries (OpenVDB, GDAL, ...)
// at load time, more than the whole synthesis of a 1200x912 frame needs; OpenImageIO is loaded
// only when another format is read or written (see image_io.cpp).
#pragma once

#include <cstdio>
#include <string>

#include "io/image_io.h"

namespace emaki::io::detail {

// 8/16-bit gray, gray+alpha, RGB, RGBA (palette and low bit depths are expanded to 8-bit).
AnyImage read_png(const std::string& path);
// Writes 8- or 16-bit PNG with 1-4 channels, values clamped to [0, 1]. `path` is written as is
// (the caller makes it atomic).
void write_png(const std::string& path, ImageView<const float> image, bool sixteen_bit,
               const std::string& error_subject);
// The same into an open file, which it closes (the caller created it, e.g. exclusively).
void write_png(std::FILE* file, ImageView<const float> image, bool sixteen_bit,
               const std::string& error_subject);

}  // namespace emaki::io::detail
