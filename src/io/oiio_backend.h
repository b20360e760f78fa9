// The OpenImageIO backend, built as a plugin module (libemaki_io_oiio.so) and loaded with
// dlopen on first use: Debian's OpenImageIO loads ~120 MB of dependent libraries, which a run
// on PNG files never needs. Each function returns an empty string on success, else the error
// message (the caller names the file).
#pragma once

#include <string>
#include <vector>

#include "io/image_io.h"

namespace emaki::io::detail {

struct OiioBackend {
  std::string (*read)(const std::string& path, const ReadOptions& options, AnyImage& out);
  std::string (*list_channels)(const std::string& path, std::vector<std::string>& out);
  // Writes to `path` exactly (the caller makes it atomic). `type`: 0 u8, 1 u16, 2 half, 3 float.
  std::string (*write)(const std::string& path, ImageView<const float> image,
                       const std::vector<std::string>& channel_names, int type);
};

// Loads the module (once); throws emaki::Error naming `subject` if it cannot.
const OiioBackend& oiio_backend(const std::string& subject);

}  // namespace emaki::io::detail

extern "C" const emaki::io::detail::OiioBackend* emaki_oiio_backend();
