#include "store/kept_fields.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/check.h"
#include "core/fnv.h"

namespace emaki::io {

namespace {

// The headers, in the machine's byte order (as the entries are).
struct FileHeader {
  char magic[8] = {'E', 'M', 'A', 'K', 'I', 'A', 'D', 'V'};
  uint32_t version = 1;
  int32_t frame = 0, width = 0, height = 0;
  uint32_t count = 0, reserved = 0;
  uint64_t digest = 0;  // of every byte after this header
};
static_assert(sizeof(FileHeader) == 40);

struct FieldHeader {
  int32_t guide = 0, patch_size = 0;
  uint64_t seed = 0;
};
static_assert(sizeof(FieldHeader) == 16);

// One field's bytes after its header: the nnf (2 x int32) and the error (float) per pixel.
std::size_t field_bytes(int width, int height) {
  return std::size_t(width) * std::size_t(height) * (2 * sizeof(int32_t) + sizeof(float));
}

// FNV-1a over 32-bit words (every part of the file is a multiple of 4 bytes).
uint64_t digest(const unsigned char* p, std::size_t size) {
  uint64_t h = kFnvOffset;
  for (std::size_t i = 0; i + 4 <= size; i += 4) {
    uint32_t w;
    std::memcpy(&w, p + i, 4);
    h = fnv1a_add(h, w);
  }
  return h;
}

}  // namespace

std::string encode_kept_fields(int frame, int width, int height,
                               const std::vector<pipeline::KeptField>& fields) {
  FileHeader h;
  h.frame = frame, h.width = width, h.height = height, h.count = uint32_t(fields.size());
  std::string out(sizeof h + fields.size() * (sizeof(FieldHeader) + field_bytes(width, height)),
                  '\0');
  unsigned char* p = reinterpret_cast<unsigned char*>(out.data()) + sizeof h;
  const auto put = [&p](const void* src, std::size_t n) {
    std::memcpy(p, src, n);
    p += n;
  };
  for (const pipeline::KeptField& k : fields) {
    const temporal::AdvectionField& f = k.field;
    CHECK_EQ(f.nnf.width(), width);
    CHECK_EQ(f.nnf.height(), height);
    CHECK_EQ(f.nnf.channels(), 2);
    CHECK_EQ(f.error.width(), width);
    CHECK_EQ(f.error.height(), height);
    CHECK_EQ(f.error.channels(), 1);
    CHECK_EQ(f.patch_size, k.patch_size);
    const FieldHeader fh{int32_t(k.guide), k.patch_size, k.seed};
    put(&fh, sizeof fh);
    for (int y = 0; y < height; ++y) put(f.nnf.row(y), 2 * sizeof(int32_t) * std::size_t(width));
    for (int y = 0; y < height; ++y) put(f.error.row(y), sizeof(float) * std::size_t(width));
  }
  h.digest =
      digest(reinterpret_cast<const unsigned char*>(out.data()) + sizeof h, out.size() - sizeof h);
  std::memcpy(out.data(), &h, sizeof h);
  return out;
}

std::vector<pipeline::KeptField> decode_kept_fields(const void* bytes, std::size_t size, int frame,
                                                    int width, int height) {
  const auto* b = static_cast<const unsigned char*>(bytes);
  FileHeader want, h;
  if (width <= 0 || height <= 0 || size < sizeof h) return {};
  std::memcpy(&h, b, sizeof h);
  if (std::memcmp(h.magic, want.magic, sizeof h.magic) != 0 || h.version != want.version ||
      h.frame != frame || h.width != width || h.height != height || h.reserved != 0)
    return {};
  const std::size_t each = sizeof(FieldHeader) + field_bytes(width, height);
  if ((size - sizeof h) % each != 0 || (size - sizeof h) / each != h.count) return {};
  if (digest(b + sizeof h, size - sizeof h) != h.digest) return {};
  std::vector<pipeline::KeptField> out;
  const unsigned char* p = b + sizeof h;
  for (uint32_t i = 0; i < h.count; ++i) {
    FieldHeader fh;
    std::memcpy(&fh, p, sizeof fh);
    p += sizeof fh;
    if ((fh.guide != int32_t(pipeline::AdvectionGuide::kPosition) &&
         fh.guide != int32_t(pipeline::AdvectionGuide::kRestPosition)) ||
        fh.patch_size < 1 || fh.patch_size > 1024)
      return {};
    pipeline::KeptField k;
    k.guide = static_cast<pipeline::AdvectionGuide>(fh.guide);
    k.patch_size = k.field.patch_size = fh.patch_size;
    k.seed = fh.seed;
    k.field.nnf.reset(width, height, 2);
    k.field.error.reset(width, height, 1);
    for (int y = 0; y < height; ++y, p += 2 * sizeof(int32_t) * std::size_t(width)) {
      int32_t* r = k.field.nnf.row(y);
      std::memcpy(r, p, 2 * sizeof(int32_t) * std::size_t(width));
      // Entries index the frame before: one outside it is not a field of this shot.
      for (int x = 0; x < width; ++x)
        if (r[2 * x] < 0 || r[2 * x] >= width || r[2 * x + 1] < 0 || r[2 * x + 1] >= height)
          return {};
    }
    for (int y = 0; y < height; ++y, p += sizeof(float) * std::size_t(width)) {
      float* r = k.field.error.row(y);
      std::memcpy(r, p, sizeof(float) * std::size_t(width));
      for (int x = 0; x < width; ++x)
        if (!std::isfinite(r[x])) return {};
    }
    out.push_back(std::move(k));
  }
  return out;
}

}  // namespace emaki::io
