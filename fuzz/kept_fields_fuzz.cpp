// libFuzzer target: the reader of a frame's kept advection fields (store/kept_fields.h), from
// bytes. No field is the expected answer to a bad file; a crash, a sanitizer report, a leak,
// more than 2 GB or 30 s on one input is a bug. The frame and size the reader expects are taken
// from the input's own header when they are small (else a fixed 16x12, which the reader must
// then refuse), and the header's digest is made right for the bytes that follow, so that
// mutations reach the fields' own checks instead of stopping at the digest.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "store/kept_fields.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  int32_t frame = 7, width = 16, height = 12;
  constexpr std::size_t kHeader = 40;
  if (size >= kHeader) {
    int32_t f = 0, w = 0, h = 0;
    std::memcpy(&f, data + 12, 4);
    std::memcpy(&w, data + 16, 4);
    std::memcpy(&h, data + 20, 4);
    if (w > 0 && w <= 64 && h > 0 && h <= 64) frame = f, width = w, height = h;
    emaki::io::seal_kept_fields(bytes.data(), bytes.size());
  }
  const std::vector<emaki::pipeline::KeptField> fields =
      emaki::io::decode_kept_fields(bytes.data(), bytes.size(), frame, width, height);
  for (const emaki::pipeline::KeptField& k : fields) {
    (void)k.field.nnf(width - 1, height - 1, 1);
    (void)k.field.error(width - 1, height - 1);
    if (!k.field.visible.empty()) (void)k.field.visible(width - 1, height - 1);
    for (const emaki::Image<float>& share : k.field.shares.share)
      (void)share(width - 1, height - 1);
  }
  return 0;
}
