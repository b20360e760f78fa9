// libFuzzer target: the PNG reader (io/png_io.cpp through io::read_image_memory), from bytes.
// An emaki::Error is the expected answer to a bad file; anything else escaping, a sanitizer
// report, a leak, more than 2 GB or 30 s on one input is a bug.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/limits.h"
#include "io/image_io.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // 2^22 pixels (64 MB as float RGBA): large enough for every size check to be reached from
  // both sides, small enough that an input claiming the largest allowed image still runs
  // fast and under libFuzzer's -malloc_limit_mb (the default 2^28 budget allows 4 GB).
  emaki::set_max_pixels(int64_t(1) << 22);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  emaki::io::ReadOptions options;
  // Odd sizes also go through picking channels by name.
  if (size % 2) options.channels = {"G", "A"};
  try {
    const emaki::io::AnyImage im = emaki::io::read_image_memory(data, size, "fuzz.png", options);
    if (im.width() > 0) (void)im.value(im.width() - 1, im.height() - 1, im.channels() - 1);
  } catch (const emaki::Error&) {
  }
  return 0;
}
