// libFuzzer target: the exemplar index reader (synth/exemplar_index.h), from bytes. emaki::Error
// is the expected answer to bad bytes; a crash, a sanitizer report, a leak, more than 2 GB or
// 30 s on one input is a bug. Inputs whose first byte is odd get their trailing digest
// recomputed, so that mutations reach the checks behind it.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/error.h"
#include "core/fnv.h"
#include "synth/exemplar_index.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  if (size > 8 && (data[0] & 1) != 0) {
    uint64_t h = emaki::kFnvOffset;
    for (std::size_t i = 0; i + 8 < size; ++i) h = emaki::fnv1a_add(h, bytes[i]);
    for (int i = 0; i < 8; ++i) bytes[size - 8 + i] = uint8_t(h >> (8 * i));
  }
  try {
    const emaki::synth::ExemplarIndex index =
        emaki::synth::deserialize_index(bytes.data(), bytes.size());
    for (const auto& level : index.levels)
      if (!level.entries.empty()) (void)level.at(level.width - 1, level.height - 1)[level.k - 1];
  } catch (const emaki::Error&) {
  }
  return 0;
}
