// libFuzzer target: the EXR readers (io/oiio_backend.cpp, OpenImageIO's OpenEXR plugin through
// an in-memory proxy; io/exr_plain.h, emaki's own reader of the files it writes, through a
// memory stream as read_image hands it an open file) and the completeness walk
// (io/exr_header.h), from bytes. An emaki::Error is
// the expected answer to a bad file; anything else escaping, a sanitizer report, a leak, more than
// 2 GB or 30 s on one input is a bug. OpenImageIO and OpenEXR are Debian's uninstrumented builds:
// coverage counts emaki's code only, while AddressSanitizer still sees their heap use.
#include <cstddef>
#include <cstdint>
#include <cstdio>

#include "core/error.h"
#include "core/limits.h"
#include "io/exr_header.h"
#include "io/exr_plain.h"
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
  // read_image's order: the header walked, then the plain reader, which declines (nullopt) what
  // it does not read.
  if (std::FILE* f = fmemopen(const_cast<uint8_t*>(data), size, "rb")) {
    try {
      emaki::io::detail::check_exr_header(f, "fuzz.exr");
      if (const auto im = emaki::io::detail::read_plain_exr(f, "fuzz.exr", options.channels))
        if (im->width() > 0) (void)im->value(im->width() - 1, im->height() - 1, im->channels() - 1);
    } catch (const emaki::Error&) {
    }
    std::fclose(f);
  }
  try {
    const emaki::io::AnyImage im = emaki::io::read_image_memory(data, size, "fuzz.exr", options);
    if (im.width() > 0) (void)im.value(im.width() - 1, im.height() - 1, im.channels() - 1);
  } catch (const emaki::Error&) {
  }
  return 0;
}
