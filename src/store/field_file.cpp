#include "store/field_file.h"

#include <zlib.h>

#include <bit>
#include <climits>
#include <cstring>
#include <vector>

#include "core/check.h"

namespace emaki::io {

namespace {

// The header, in the machine's byte order (as the entries are).
struct FieldHeader {
  char magic[8] = {'E', 'M', 'A', 'K', 'I', 'N', 'N', 'F'};
  uint32_t version = 2;  // 1: the entries as they are, uncompressed
  int32_t frame = 0, width = 0, height = 0;
  uint64_t digest = 0;
};
static_assert(sizeof(FieldHeader) == kFieldHeaderBytes);

// zlib level 1: measured on the example's base layer at 960x540 (docs/design/warm-start.md), level
// 6 makes the file a fifth smaller for several times the time.
constexpr int kLevel = 1;

std::size_t raw_bytes(int width, int height) {
  return sizeof(uint32_t) * 2 * std::size_t(width) * std::size_t(height);
}

}  // namespace

std::size_t max_field_file_bytes(int width, int height) {
  if (width <= 0 || height <= 0) return kFieldHeaderBytes;
  return kFieldHeaderBytes + compressBound(uLong(raw_bytes(width, height)));
}

std::string encode_field(int frame, ImageView<const int32_t> nnf, uint64_t digest) {
  CHECK_EQ(nnf.channels, 2);
  FieldHeader h;
  h.frame = frame, h.width = nnf.width, h.height = nnf.height, h.digest = digest;
  std::string out(reinterpret_cast<const char*>(&h), sizeof h);
  z_stream z{};
  CHECK_EQ(deflateInit(&z, kLevel), Z_OK);
  std::vector<uint32_t> row(2 * std::size_t(nnf.width));
  std::vector<unsigned char> chunk(1 << 16);
  for (int y = 0; y < nnf.height; ++y) {
    const int32_t* r = nnf.row(y);
    uint32_t left[2] = {0, 0};
    for (std::size_t i = 0; i < row.size(); ++i) {
      const uint32_t v = std::bit_cast<uint32_t>(r[i]);
      row[i] = v - left[i & 1];  // wraps: any int32 pair codes and decodes exactly
      left[i & 1] = v;
    }
    z.next_in = reinterpret_cast<Bytef*>(row.data());
    z.avail_in = uInt(row.size() * sizeof(uint32_t));
    const int flush = y + 1 == nnf.height ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = chunk.data();
      z.avail_out = uInt(chunk.size());
      const int ret = deflate(&z, flush);
      CHECK(ret == Z_OK || ret == Z_STREAM_END || ret == Z_BUF_ERROR);
      out.append(reinterpret_cast<const char*>(chunk.data()), chunk.size() - z.avail_out);
    } while (z.avail_out == 0);
  }
  deflateEnd(&z);
  return out;
}

Image<int32_t> decode_field(const void* bytes, std::size_t size, const FieldKey& want) {
  // The size first: nothing is allocated for bytes that cannot be a field of `want`'s size.
  if (want.width <= 0 || want.height <= 0 || size < kFieldHeaderBytes ||
      size > max_field_file_bytes(want.width, want.height) || size - kFieldHeaderBytes > UINT_MAX)
    return {};
  FieldHeader expect, have;
  expect.frame = want.frame, expect.width = want.width, expect.height = want.height;
  expect.digest = want.digest;
  std::memcpy(&have, bytes, sizeof have);
  if (std::memcmp(&have, &expect, sizeof have) != 0) return {};
  z_stream z{};
  if (inflateInit(&z) != Z_OK) return {};
  z.next_in = const_cast<Bytef*>(static_cast<const Bytef*>(bytes) + kFieldHeaderBytes);
  z.avail_in = uInt(size - kFieldHeaderBytes);
  Image<int32_t> nnf(want.width, want.height, 2);
  std::vector<uint32_t> row(2 * std::size_t(want.width));
  bool ok = true;
  int ret = Z_OK;
  for (int y = 0; y < want.height && ok; ++y) {
    z.next_out = reinterpret_cast<Bytef*>(row.data());
    z.avail_out = uInt(row.size() * sizeof(uint32_t));
    while (z.avail_out > 0 && ret == Z_OK) ret = inflate(&z, Z_NO_FLUSH);
    // A full row, and the stream's end only after the last one.
    ok = z.avail_out == 0 && (ret == Z_OK || (ret == Z_STREAM_END && y + 1 == want.height));
    int32_t* r = nnf.row(y);
    uint32_t left[2] = {0, 0};
    for (std::size_t i = 0; i < row.size() && ok; ++i) {
      left[i & 1] += row[i];
      r[i] = std::bit_cast<int32_t>(left[i & 1]);
    }
  }
  if (ok && ret == Z_OK) {
    // Every entry is in: the stream must end here, without a byte more.
    unsigned char extra = 0;
    z.next_out = &extra;
    z.avail_out = 1;
    ret = inflate(&z, Z_FINISH);
    ok = ret == Z_STREAM_END && z.avail_out == 1;
  }
  ok = ok && z.avail_in == 0;  // nothing after the stream
  inflateEnd(&z);
  return ok ? std::move(nnf) : Image<int32_t>();
}

}  // namespace emaki::io
