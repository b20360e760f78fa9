// libFuzzer target: the reader of a temporal layer's warm-start field file (store/field_file.h),
// from bytes. An empty field is the expected answer to a bad file; a crash, a sanitizer report,
// a leak, more than 2 GB or 30 s on one input is a bug. The size the reader expects is taken
// from the input's own header when it is small (so that inputs reach the zlib stream), else a
// fixed 16x12: the reader must then refuse the header.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "store/field_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  emaki::io::FieldKey want{7, 16, 12, 0x1234};
  if (size >= emaki::io::kFieldHeaderBytes) {
    int32_t frame = 0, width = 0, height = 0;
    std::memcpy(&frame, data + 12, 4);
    std::memcpy(&width, data + 16, 4);
    std::memcpy(&height, data + 20, 4);
    if (width > 0 && width <= 512 && height > 0 && height <= 512) {
      want.frame = frame, want.width = width, want.height = height;
      std::memcpy(&want.digest, data + 24, 8);
    }
  }
  const emaki::Image<int32_t> nnf = emaki::io::decode_field(data, size, want);
  if (!nnf.empty()) (void)nnf(nnf.width() - 1, nnf.height() - 1, 1);
  return 0;
}
