// libFuzzer target: the EXR reader (io/oiio_backend.cpp, OpenImageIO's OpenEXR plugin through
// an in-memory proxy) and the completeness walk (io/exr_header.h), from bytes. An emaki::Error is
// the expected answer to a bad file; anything else escaping, a sanitizer report, a leak, more than
// 2 GB or 30 s on one input is a bug. OpenImageIO and OpenEXR are Debian's uninstrumented builds:
// coverage counts emaki's code only, while AddressSanitizer still sees their heap use.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/limits.h"
#include "io/exr_header.h"
#include "io/image_io.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // See png_fuzz.cpp: a budget that keeps the largest allowed image fast and under
  // libFuzzer's -malloc_limit_mb.
  emaki::set_max_pixels(int64_t(1) << 22);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  emaki::io::ReadOptions options;
  // Odd sizes go through the named-channel search across parts (multilayer files).
  if (size % 2) options.channels = {"R", "diffuse.G", "position.Z"};
  try {
    // The output store's check of a finished file: the headers, the chunk table, the last chunk.
    emaki::io::detail::check_exr_complete(data, size, "fuzz.exr");
  } catch (const emaki::Error&) {
  }
  try {
    const emaki::io::AnyImage im = emaki::io::read_image_memory(data, size, "fuzz.exr", options);
    if (im.width() > 0) (void)im.value(im.width() - 1, im.height() - 1, im.channels() - 1);
  } catch (const emaki::Error&) {
  }
  return 0;
}
