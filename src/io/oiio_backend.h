// The OpenImageIO backend, built as a plugin module (libemaki_io_oiio.so) and loaded with
// dlopen on first use: Debian's OpenImageIO loads ~120 MB of dependent libraries, which a run
// on PNG files never needs. Each function returns an empty string on success, else the error
// message (the caller names the file).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "io/image_io.h"

namespace emaki::io::detail {

// Where a read comes from: the file `path`, or, when `data` is set, `size` bytes in memory, or,
// when `file` is set, that file already open (the caller's, read from its start and left open):
// then `path` is only a name whose extension picks the format.
struct OiioSource {
  std::string path;
  const void* data = nullptr;
  std::size_t size = 0;
  std::FILE* file = nullptr;
};

struct OiioBackend {
  // `max_pixels` is the caller's pixel budget (core/limits.h), passed because the module, loaded
  // with RTLD_LOCAL, may hold its own copy of the process-wide setting. Every header (data
  // window, tiles, channels, parts) is checked against it before a pixel is read.
  std::string (*read)(const OiioSource& source, const ReadOptions& options, int64_t max_pixels,
                      AnyImage& out);
  std::string (*list_channels)(const OiioSource& source, std::vector<std::string>& out);
  // Writes to `path` exactly (the caller makes it atomic). `type`: 0 u8, 1 u16, 2 half, 3 float;
  // the options' compression, EXR attributes and chromaticities go into the header.
  std::string (*write)(const std::string& path, ImageView<const float> image,
                       const WriteOptions& options, int type);
};

// Loads the module (once); throws emaki::Error naming `subject` if it cannot.
const OiioBackend& oiio_backend(const std::string& subject);

}  // namespace emaki::io::detail

extern "C" const emaki::io::detail::OiioBackend* emaki_oiio_backend();
