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
  uint32_t version = 2;  // 2: the digest in four chains (FnvLanes)
  int32_t frame = 0, width = 0, height = 0;
  uint32_t count = 0, reserved = 0;
  uint64_t digest = 0;  // of every byte after this header
};
static_assert(sizeof(FileHeader) == 40);

struct FieldHeader {
  int32_t guide = 0, patch_size = 0;
  uint64_t seed = 0;
  int32_t visible = 0;         // 1: the visible_before() map follows the errors
  int32_t shares_radius = -1;  // IdShares::radius (-1: no shares)
  uint32_t ids = 0, reserved = 0;
};
static_assert(sizeof(FieldHeader) == 32);

std::size_t pixels(int width, int height) {
  return std::size_t(width) * std::size_t(height);
}

// The visible map's bytes, padded to whole 32-bit words (the digest's unit).
std::size_t visible_bytes(int width, int height) {
  return (pixels(width, height) + 3) / 4 * 4;
}

// FNV-1a in four chains (every part of the file is a multiple of 4 bytes): every layer task
// checks each frame's file (13 MB at 960x540).
uint64_t digest(const unsigned char* p, std::size_t size) {
  FnvLanes lanes;
  lanes.add(p, size);
  return lanes.value();
}

// Rows of `image` (width x height x channels of T) to or from consecutive bytes.
template <typename T>
void put_rows(std::string& out, const Image<T>& image) {
  for (int y = 0; y < image.height(); ++y)
    out.append(reinterpret_cast<const char*>(image.row(y)),
               sizeof(T) * std::size_t(image.width()) * std::size_t(image.channels()));
}
template <typename T>
const unsigned char* get_rows(const unsigned char* p, Image<T>& image) {
  const std::size_t row = sizeof(T) * std::size_t(image.width()) * std::size_t(image.channels());
  for (int y = 0; y < image.height(); ++y, p += row) std::memcpy(image.row(y), p, row);
  return p;
}

bool all_finite(const Image<float>& image) {
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      if (!std::isfinite(image(x, y))) return false;
  return true;
}

// One field's entries from `p` (its header `fh` read), or false when they do not hold.
bool get_field(const FieldHeader& fh, const unsigned char* p, int width, int height,
               temporal::AdvectionField& f) {
  f.patch_size = fh.patch_size;
  f.nnf.reset(width, height, 2);
  f.error.reset(width, height, 1);
  p = get_rows(p, f.nnf);
  p = get_rows(p, f.error);
  // Entries index the frame before: one outside it is not a field of this shot.
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (f.nnf(x, y, 0) < 0 || f.nnf(x, y, 0) >= width || f.nnf(x, y, 1) < 0 ||
          f.nnf(x, y, 1) >= height)
        return false;
  if (!all_finite(f.error)) return false;
  if (fh.visible) {
    f.visible.reset(width, height, 1);
    get_rows(p, f.visible);
    p += visible_bytes(width, height);
  }
  if (fh.shares_radius < 0) return true;
  f.shares.radius = fh.shares_radius;
  f.shares.ids.resize(fh.ids);
  if (fh.ids > 0) std::memcpy(f.shares.ids.data(), p, sizeof(float) * fh.ids);
  p += sizeof(float) * fh.ids;
  for (uint32_t i = 0; i < fh.ids; ++i) {
    Image<float> share(width, height, 1);
    p = get_rows(p, share);
    if (!all_finite(share)) return false;
    f.shares.share.push_back(std::move(share));
  }
  return true;
}

}  // namespace

std::string encode_kept_fields(int frame, int width, int height,
                               const std::vector<pipeline::KeptField>& fields) {
  FileHeader h;
  h.frame = frame, h.width = width, h.height = height, h.count = uint32_t(fields.size());
  std::string out(sizeof h, '\0');
  for (const pipeline::KeptField& k : fields) {
    const temporal::AdvectionField& f = k.field;
    CHECK_EQ(f.patch_size, k.patch_size);
    CHECK(f.nnf.width() == width && f.nnf.height() == height && f.nnf.channels() == 2);
    CHECK(f.error.width() == width && f.error.height() == height && f.error.channels() == 1);
    FieldHeader fh;
    fh.guide = int32_t(k.guide), fh.patch_size = k.patch_size, fh.seed = k.seed;
    fh.visible = f.visible.empty() ? 0 : 1;
    fh.shares_radius = f.shares.empty() ? -1 : f.shares.radius;
    fh.ids = f.shares.empty() ? 0 : uint32_t(f.shares.ids.size());
    out.append(reinterpret_cast<const char*>(&fh), sizeof fh);
    put_rows(out, f.nnf);
    put_rows(out, f.error);
    if (fh.visible) {
      CHECK(f.visible.width() == width && f.visible.height() == height &&
            f.visible.channels() == 1);
      put_rows(out, f.visible);
      out.append(visible_bytes(width, height) - pixels(width, height), '\0');
    }
    if (fh.shares_radius < 0) continue;
    CHECK_EQ(f.shares.share.size(), f.shares.ids.size());
    out.append(reinterpret_cast<const char*>(f.shares.ids.data()), sizeof(float) * fh.ids);
    for (const Image<float>& share : f.shares.share) {
      CHECK(share.width() == width && share.height() == height && share.channels() == 1);
      put_rows(out, share);
    }
  }
  h.digest =
      digest(reinterpret_cast<const unsigned char*>(out.data()) + sizeof h, out.size() - sizeof h);
  std::memcpy(out.data(), &h, sizeof h);
  return out;
}

void seal_kept_fields(void* bytes, std::size_t size) {
  FileHeader h;
  CHECK_GE(size, sizeof h);
  auto* b = static_cast<unsigned char*>(bytes);
  std::memcpy(&h, b, sizeof h);
  h.digest = digest(b + sizeof h, size - sizeof h);
  std::memcpy(b, &h, sizeof h);
}

std::vector<pipeline::KeptField> decode_kept_fields(const void* bytes, std::size_t size, int frame,
                                                    int width, int height) {
  const auto* b = static_cast<const unsigned char*>(bytes);
  FileHeader want, h;
  if (width <= 0 || height <= 0 || size < sizeof h) return {};
  std::memcpy(&h, b, sizeof h);
  if (std::memcmp(h.magic, want.magic, sizeof h.magic) != 0 || h.version != want.version ||
      h.frame != frame || h.width != width || h.height != height || h.reserved != 0 ||
      digest(b + sizeof h, size - sizeof h) != h.digest)
    return {};
  std::vector<pipeline::KeptField> out;
  std::size_t at = sizeof h;
  const std::size_t n = pixels(width, height);
  for (uint32_t i = 0; i < h.count; ++i) {
    FieldHeader fh;
    if (size - at < sizeof fh) return {};
    std::memcpy(&fh, b + at, sizeof fh);
    at += sizeof fh;
    if ((fh.guide != int32_t(pipeline::AdvectionGuide::kPosition) &&
         fh.guide != int32_t(pipeline::AdvectionGuide::kRestPosition)) ||
        fh.patch_size < 1 || fh.patch_size > 1024 || (fh.visible != 0 && fh.visible != 1) ||
        fh.shares_radius < -1 || (fh.shares_radius < 0 && fh.ids != 0) || fh.reserved != 0)
      return {};
    // What the header says follows, counted before anything is allocated for it.
    const std::size_t share_bytes = sizeof(float) * (1 + n);
    const std::size_t fixed = n * 12 + (fh.visible ? visible_bytes(width, height) : 0);
    if (size - at < fixed || (size - at - fixed) / share_bytes < fh.ids) return {};
    pipeline::KeptField k;
    k.guide = static_cast<pipeline::AdvectionGuide>(fh.guide);
    k.patch_size = fh.patch_size;
    k.seed = fh.seed;
    if (!get_field(fh, b + at, width, height, k.field)) return {};
    at += fixed + share_bytes * fh.ids;
    out.push_back(std::move(k));
  }
  if (at != size) return {};
  return out;
}

}  // namespace emaki::io
