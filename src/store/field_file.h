// The file of a temporal layer's field at one frame (the next frame's warm start,
// pipeline::Store::write_field): a 32-byte header, then the field's entries, each as the
// difference to its left neighbour (the first of a row as it is), zlib-compressed. A field is
// mostly runs of +1 steps, so it shrinks about tenfold (docs/design/warm-start.md has the figures).
// The reader takes the bytes as hostile input: it gives an empty field, never a crash, for
// anything but the exact header the caller expects and a zlib stream that decompresses to
// exactly width x height x 2 entries with nothing after it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/image.h"

namespace emaki::io {

// What a field file must be to be read: its frame, the shot's size, and the digest of the layer
// value it made (pipeline::value_digest).
struct FieldKey {
  int frame = 0, width = 0, height = 0;
  uint64_t digest = 0;
};

inline constexpr std::size_t kFieldHeaderBytes = 32;

// The largest file a field of width x height can be: a file larger than this is not read (nor
// anything allocated for it).
std::size_t max_field_file_bytes(int width, int height);

// The whole file: the header (with nnf's size) and the compressed entries. `nnf`: 2 channels.
std::string encode_field(int frame, ImageView<const int32_t> nnf, uint64_t digest);

// The field in `bytes`, or an empty image when they are not exactly a field file with `want`'s
// header. Nothing is allocated beyond `want`'s size.
Image<int32_t> decode_field(const void* bytes, std::size_t size, const FieldKey& want);

}  // namespace emaki::io
