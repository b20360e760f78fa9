#include "io/exr_plain.h"

#include <libdeflate.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <memory>

#define IMATH_HALF_NO_LOOKUP_TABLE  // the conversions inline: no link to libImath
#include <Imath/half.h>

#include "core/error.h"
#include "core/parallel.h"
#include "io/read_limits.h"

namespace emaki::io::detail {
namespace {

// A header is read whole into memory; emaki's are a few hundred bytes (24 channels: ~600).
constexpr std::size_t kMaxHeader = std::size_t(1) << 20;
// OpenEXR's version flags that make a file something other than one scanline part.
constexpr uint32_t kNotScanlinePart = 0x200 | 0x800 | 0x1000;  // tiled, deep, multipart
constexpr int32_t kHalf = 1, kFloat = 2;                       // channel pixel types
// Compressions: none, ZIPS (one row a chunk) and ZIP (16 rows a chunk).
constexpr int kNone = 0, kZips = 2, kZip = 3;
// OpenEXR's own default zlib level for ZIP. The zlib streams are libdeflate's: at this level 1.7x
// as fast as zlib's to write and 2-3x to read on emaki's layers, and a little smaller.
constexpr int kZipLevel = 4;

// This thread's libdeflate (de)compressor, made on first use: they hold tables of a few hundred
// KB that are not to be made again for every chunk, and may not be shared between threads.
libdeflate_compressor* thread_compressor() {
  thread_local std::unique_ptr<libdeflate_compressor, void (*)(libdeflate_compressor*)> c(
      libdeflate_alloc_compressor(kZipLevel), &libdeflate_free_compressor);
  return c.get();
}

libdeflate_decompressor* thread_decompressor() {
  thread_local std::unique_ptr<libdeflate_decompressor, void (*)(libdeflate_decompressor*)> d(
      libdeflate_alloc_decompressor(), &libdeflate_free_decompressor);
  return d.get();
}

struct Channel {
  std::string name;
  int32_t type = -1, x_sampling = 0, y_sampling = 0;
};

struct Header {
  std::vector<Channel> channels;
  int compression = -1;
  bool has_window = false;
  int32_t window[4] = {};  // xmin, ymin, xmax, ymax
  std::size_t end = 0;     // where the offset table starts
};

// A cursor over the header's bytes; every read is bounds-checked (false past the end).
class Bytes {
 public:
  Bytes(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}
  std::size_t position() const { return at_; }
  bool cstring(std::string& out) {
    const auto* end = static_cast<const unsigned char*>(std::memchr(data_ + at_, 0, size_ - at_));
    if (end == nullptr) return false;
    out.assign(reinterpret_cast<const char*>(data_ + at_), std::size_t(end - (data_ + at_)));
    at_ = std::size_t(end - data_) + 1;
    return true;
  }
  bool i32(int32_t& v) {
    if (size_ - at_ < 4) return false;
    uint32_t u = 0;
    for (int k = 3; k >= 0; --k) u = u << 8 | data_[at_ + std::size_t(k)];
    v = int32_t(u);
    at_ += 4;
    return true;
  }
  bool skip(std::size_t n) {
    if (size_ - at_ < n) return false;
    at_ += n;
    return true;
  }
  const unsigned char* here() const { return data_ + at_; }

 private:
  const unsigned char* data_;
  std::size_t size_, at_ = 0;
};

bool channel_list(const unsigned char* data, std::size_t size, std::vector<Channel>& out) {
  Bytes b(data, size);
  for (;;) {
    Channel c;
    if (!b.cstring(c.name)) return false;
    if (c.name.empty()) return true;
    if (!b.i32(c.type) || !b.skip(4) || !b.i32(c.x_sampling) || !b.i32(c.y_sampling)) return false;
    out.push_back(std::move(c));
  }
}

bool parse_header(const unsigned char* data, std::size_t size, Header& h) {
  Bytes b(data, size);
  int32_t magic = 0, version = 0;
  if (!b.i32(magic) || magic != 20000630 || !b.i32(version)) return false;
  if ((version & 0xff) != 2 || (uint32_t(version) & kNotScanlinePart) != 0) return false;
  for (;;) {
    std::string name, type;
    if (!b.cstring(name)) return false;
    if (name.empty()) break;
    int32_t n = 0;
    if (!b.cstring(type) || !b.i32(n) || n < 0) return false;
    const unsigned char* value = b.here();
    if (!b.skip(std::size_t(n))) return false;
    if (name == "channels") {
      if (type != "chlist" || !channel_list(value, std::size_t(n), h.channels)) return false;
    } else if (name == "compression") {
      if (n != 1) return false;
      h.compression = value[0];
    } else if (name == "dataWindow") {
      if (type != "box2i" || n != 16) return false;
      Bytes w(value, 16);
      for (int32_t& v : h.window) w.i32(v);
      h.has_window = true;
    }
  }
  h.end = b.position();
  return true;
}

bool read_at(int fd, uint64_t offset, void* out, std::size_t n) {
  auto* p = static_cast<unsigned char*>(out);
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, off_t(offset));
    if (got <= 0) return false;
    p += got, offset += uint64_t(got), n -= std::size_t(got);
  }
  return true;
}

int rows_per_chunk(int compression) {
  return compression == kZip ? 16 : 1;
}

// OpenEXR's ZIP filter on a chunk's bytes: even and odd bytes split into halves, then each byte
// as the difference from the one before (zlib then finds more repeats). Both steps in one pass,
// each half a loop of its own that the compiler vectorizes (as one loop, byte by byte, this
// was a fifth of a composite task's instructions).
void zip_filter(const unsigned char* raw, std::size_t n, unsigned char* out) {
  if (n == 0) return;
  const std::size_t even = (n + 1) / 2, odd = n / 2;
  unsigned char* t1 = out;
  unsigned char* t2 = out + even;
  t1[0] = raw[0];
  for (std::size_t j = 1; j < even; ++j)
    t1[j] = static_cast<unsigned char>(raw[2 * j] - raw[2 * j - 2] + 128);
  if (odd == 0) return;
  t2[0] = static_cast<unsigned char>(raw[1] - raw[2 * (even - 1)] + 128);
  for (std::size_t j = 1; j < odd; ++j)
    t2[j] = static_cast<unsigned char>(raw[2 * j + 1] - raw[2 * j - 1] + 128);
}

// zip_filter undone: the running sum of the differences, each byte written to its place.
void zip_unfilter(const unsigned char* filtered, std::size_t n, unsigned char* raw) {
  if (n == 0) return;
  const std::size_t even = (n + 1) / 2;
  unsigned char acc = filtered[0];
  raw[0] = acc;
  for (std::size_t j = 1; j < even; ++j)
    raw[2 * j] = acc = static_cast<unsigned char>(acc + filtered[j] - 128);
  for (std::size_t j = 0; j < n / 2; ++j)
    raw[2 * j + 1] = acc = static_cast<unsigned char>(acc + filtered[even + j] - 128);
}

// The channels emaki's layer files hold, in the order OpenImageIO gives them: a whole-file read
// takes this path only for these.
const std::vector<std::vector<std::string>>& known_orders() {
  static const std::vector<std::vector<std::string>> k = {
      {"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  return k;
}

// What a read takes from a plain file's header: the channels asked for, where each is in a row.
struct Layout {
  Header h;
  std::vector<std::string> names;  // the image's channels
  std::vector<int> from;           // the file channel of each
  std::vector<std::size_t> start;  // where each file channel's samples start in a row, per pixel
  std::size_t pixel_bytes = 0;     // of a row, per pixel
  int64_t width = 0, height = 0;
};

bool plan_read(const Header& h, const std::vector<std::string>& channels, Layout& l) {
  if ((h.compression != kNone && h.compression != kZips && h.compression != kZip) ||
      !h.has_window || h.channels.empty())
    return false;
  for (const Channel& c : h.channels) {
    if ((c.type != kFloat && c.type != kHalf) || c.x_sampling != 1 || c.y_sampling != 1)
      return false;
    l.start.push_back(l.pixel_bytes);
    l.pixel_bytes += c.type == kHalf ? 2 : 4;
  }
  l.h = h;
  l.names = channels;
  if (l.names.empty()) {
    // A whole-file read: only where OpenImageIO's channel order is known.
    std::vector<std::string> have;
    for (const Channel& c : h.channels) have.push_back(c.name);
    for (const std::vector<std::string>& order : known_orders()) {
      std::vector<std::string> sorted = order;
      std::sort(sorted.begin(), sorted.end());
      if (have == sorted) l.names = order;
    }
    if (l.names.empty()) return false;
  }
  for (const std::string& want : l.names) {
    const auto it = std::find_if(h.channels.begin(), h.channels.end(),
                                 [&](const Channel& c) { return c.name == want; });
    if (it == h.channels.end()) return false;
    l.from.push_back(int(it - h.channels.begin()));
  }
  l.width = int64_t(h.window[2]) - h.window[0] + 1;
  l.height = int64_t(h.window[3]) - h.window[1] + 1;
  return true;
}

// One row's samples into the image's row `dst`; returns nonzero when one is a NaN or Inf (an
// all-ones exponent).
uint32_t scatter_row(const Layout& l, const unsigned char* row, float* dst) {
  const std::size_t w = std::size_t(l.width), n = l.names.size();
  uint32_t bad = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t c = std::size_t(l.from[i]);
    const unsigned char* src = row + l.start[c] * w;
    if (l.h.channels[c].type == kFloat) {
      for (std::size_t x = 0; x < w; ++x) {
        uint32_t bits;
        std::memcpy(&bits, src + x * 4, 4);
        bad |= ~bits & 0x7f800000u ? 0u : 1u;
        dst[x * n + i] = std::bit_cast<float>(bits);
      }
    } else {
      for (std::size_t x = 0; x < w; ++x) {
        uint16_t bits;
        std::memcpy(&bits, src + x * 2, 2);
        bad |= ~bits & 0x7c00u ? 0u : 1u;
        dst[x * n + i] = imath_half_to_float(bits);
      }
    }
  }
  return bad;
}

// The offset table (one entry per chunk), then each chunk: its first y, its byte count, and its
// rows, each row every channel's samples in the header's order (filtered and deflated under ZIP,
// unless that came out no smaller). False for anything else, or a NaN or Inf.
bool read_chunks(int fd, uint64_t file_size, const Layout& l, Image<float>& out) {
  const int lines = rows_per_chunk(l.h.compression);
  const int64_t chunks = (l.height + lines - 1) / lines;
  const std::size_t row_bytes = std::size_t(l.width) * l.pixel_bytes;
  if (l.h.end > file_size || uint64_t(chunks) > (file_size - l.h.end) / 8) return false;
  std::vector<uint64_t> offsets(static_cast<std::size_t>(chunks));
  if (!read_at(fd, l.h.end, offsets.data(), offsets.size() * 8)) return false;
  std::vector<unsigned char> chunk, filtered(row_bytes * std::size_t(lines)),
      raw(row_bytes * std::size_t(lines));
  std::vector<bool> seen(std::size_t(chunks), false);
  uint32_t bad = 0;
  for (const uint64_t offset : offsets) {
    int32_t prefix[2];  // y, bytes
    if (offset > file_size || file_size - offset < 8 || !read_at(fd, offset, prefix, 8))
      return false;
    const int64_t first = int64_t(prefix[0]) - l.h.window[1];
    if (first < 0 || first >= l.height || first % lines != 0 || seen[std::size_t(first / lines)])
      return false;
    seen[std::size_t(first / lines)] = true;
    const int rows = int(std::min<int64_t>(lines, l.height - first));
    const std::size_t expect = row_bytes * std::size_t(rows);
    const int32_t bytes = prefix[1];
    if (bytes <= 0 || uint64_t(bytes) > file_size - offset - 8 || std::size_t(bytes) > expect ||
        (l.h.compression == kNone && std::size_t(bytes) != expect))
      return false;
    chunk.resize(std::size_t(bytes));
    if (!read_at(fd, offset + 8, chunk.data(), chunk.size())) return false;
    const unsigned char* data = chunk.data();
    if (std::size_t(bytes) < expect) {
      libdeflate_decompressor* d = thread_decompressor();
      if (!d || libdeflate_zlib_decompress(d, chunk.data(), std::size_t(bytes), filtered.data(),
                                           expect, nullptr) != LIBDEFLATE_SUCCESS)
        return false;
      zip_unfilter(filtered.data(), expect, raw.data());
      data = raw.data();
    }
    for (int r = 0; r < rows; ++r)
      bad |= scatter_row(l, data + std::size_t(r) * row_bytes, out.row(int(first) + r));
  }
  // Every chunk was read once (as many as the table holds, each a distinct one); a non-finite
  // sample is left to the general reader, which names it.
  return bad == 0;
}

// The header of a file of `names` (stored in `order`), up to the offset table.
std::string plain_header(const std::vector<std::string>& names, const std::vector<int>& order,
                         const WriteOptions& options, int compression, bool half, int width,
                         int height) {
  std::string out("\x76\x2f\x31\x01", 4);
  bool long_names = false;
  auto put = [&out](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
  auto put_i32 = [&](int32_t v) { put(&v, 4); };
  auto put_f32 = [&](float v) { put(&v, 4); };
  auto attribute = [&](const std::string& name, const char* type, std::size_t size) {
    long_names |= name.size() > 31;
    out += name, out += '\0', out += type, out += '\0';
    put_i32(int32_t(size));
  };
  put_i32(2);
  std::string chlist;
  for (const int c : order) {
    const std::string& name = names[std::size_t(c)];
    long_names |= name.size() > 31;
    chlist += name, chlist += '\0';
    const int32_t fields[4] = {half ? kHalf : kFloat, 0, 1, 1};  // type, pLinear + reserved, xs, ys
    chlist.append(reinterpret_cast<const char*>(fields), 16);
  }
  chlist += '\0';
  // The attributes OpenEXR requires, the chromaticities and the string attributes.
  attribute("channels", "chlist", chlist.size());
  out += chlist;
  if (options.chromaticities.size() == 8) {
    attribute("chromaticities", "chromaticities", 32);
    for (const float v : options.chromaticities) put_f32(v);
  }
  attribute("compression", "compression", 1);
  out += char(compression);
  const int32_t window[4] = {0, 0, width - 1, height - 1};
  attribute("dataWindow", "box2i", 16);
  put(window, 16);
  attribute("displayWindow", "box2i", 16);
  put(window, 16);
  attribute("lineOrder", "lineOrder", 1);
  out += '\0';  // increasing y
  attribute("pixelAspectRatio", "float", 4);
  put_f32(1.f);
  attribute("screenWindowCenter", "v2f", 8);
  put_f32(0.f), put_f32(0.f);
  attribute("screenWindowWidth", "float", 4);
  put_f32(1.f);
  for (const auto& [key, value] : options.attributes) {
    attribute(key, "string", value.size());
    out += value;
  }
  out += '\0';
  if (long_names) {
    const int32_t version = 2 | 0x400;
    std::memcpy(out.data() + 4, &version, 4);
  }
  return out;
}

// Rows [first, first + rows) of `image` as a chunk's bytes: per row, each channel in `order`.
void pack_rows(ImageView<const float> image, int first, int rows, const std::vector<int>& order,
               bool half, unsigned char* dst) {
  const std::size_t w = std::size_t(image.width), sample = half ? 2 : 4;
  for (int r = 0; r < rows; ++r) {
    const float* src = image.row(first + r);
    for (const int c : order) {
      for (std::size_t x = 0; x < w; ++x) {
        const float v = src[x * std::size_t(image.channels) + std::size_t(c)];
        if (half) {
          const uint16_t bits = imath_float_to_half(v);
          std::memcpy(dst + x * 2, &bits, 2);
        } else {
          std::memcpy(dst + x * 4, &v, 4);
        }
      }
      dst += w * sample;
    }
  }
}

// A chunk's scratch, written before it is read (not zeroed): the packed rows and, under ZIP,
// the filtered rows and the deflated bytes.
struct ChunkScratch {
  ChunkScratch(std::size_t most, bool zip)
      : bound(zip ? libdeflate_zlib_compress_bound(nullptr, most) : 0),
        raw(std::make_unique_for_overwrite<unsigned char[]>(most)),
        filtered(std::make_unique_for_overwrite<unsigned char[]>(zip ? most : 0)),
        packed(std::make_unique_for_overwrite<unsigned char[]>(bound)) {}
  std::size_t bound;
  std::unique_ptr<unsigned char[]> raw, filtered, packed;
};

// Rows [first, first + rows) of `image` as a chunk, into `piece`: its first y, its byte count and
// its rows, ZIP-filtered and deflated (when `s` is a ZIP scratch) unless that comes out no
// smaller. False when the compressor cannot be made (out of memory).
bool encode_chunk(ImageView<const float> image, int first, int rows, const std::vector<int>& order,
                  bool half, std::size_t row_bytes, ChunkScratch& s, std::string& piece) {
  const std::size_t n = row_bytes * std::size_t(rows);
  pack_rows(image, first, rows, order, half, s.raw.get());
  const unsigned char* data = s.raw.get();
  std::size_t size = n;
  if (s.bound > 0) {
    zip_filter(s.raw.get(), n, s.filtered.get());
    libdeflate_compressor* c = thread_compressor();
    const std::size_t got =
        c ? libdeflate_zlib_compress(c, s.filtered.get(), n, s.packed.get(), s.bound) : 0;
    if (got == 0) return false;
    if (got < n) data = s.packed.get(), size = got;
  }
  const int32_t prefix[2] = {first, int32_t(size)};
  piece.assign(reinterpret_cast<const char*>(prefix), 8);
  piece.append(reinterpret_cast<const char*>(data), size);
  return true;
}

}  // namespace

std::optional<AnyImage> read_plain_exr(std::FILE* f, const std::string& path,
                                       const std::vector<std::string>& channels) {
  if constexpr (std::endian::native != std::endian::little) return std::nullopt;
  const int fd = ::fileno(f);
  struct stat st {};
  if (fd < 0 || ::fstat(fd, &st) != 0 || st.st_size <= 0) return std::nullopt;
  const uint64_t file_size = uint64_t(st.st_size);
  std::vector<unsigned char> head(std::min<uint64_t>(file_size, kMaxHeader));
  Header h;
  Layout l;
  if (!read_at(fd, 0, head.data(), head.size()) || !parse_header(head.data(), head.size(), h) ||
      !plan_read(h, channels, l))
    return std::nullopt;
  Image<float> out;
  try {
    check_image_alloc<float>(path, l.width, l.height, int64_t(l.names.size()));
    out = allocate_image<float>(path, int(l.width), int(l.height), int(l.names.size()));
  } catch (const Error&) {
    return std::nullopt;
  }
  if (!read_chunks(fd, file_size, l, out)) return std::nullopt;
  AnyImage result;
  result.image = std::move(out);
  result.channel_names = std::move(l.names);
  return result;
}

std::optional<std::string> encode_plain_exr(ImageView<const float> image,
                                            const WriteOptions& options, bool half) {
  if constexpr (std::endian::native != std::endian::little) return std::nullopt;
  const int compression = options.compression == "none"   ? kNone
                          : options.compression == "zips" ? kZips
                          : options.compression == "zip"  ? kZip
                                                          : -1;
  const std::vector<std::string>& names = options.channel_names;
  if (compression < 0 || image.empty() || int(names.size()) != image.channels) return std::nullopt;
  std::vector<int> order(names.size());  // the image channel of each file channel (sorted)
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = int(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return names[a] < names[b]; });
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::string& name = names[std::size_t(order[i])];
    if (name.empty() || name.size() > 255 || name.find('\0') != std::string::npos ||
        (i > 0 && name == names[std::size_t(order[i - 1])]))
      return std::nullopt;
  }
  static const char* const kWritten[] = {
      "channels",  "chromaticities",   "compression",        "dataWindow",       "displayWindow",
      "lineOrder", "pixelAspectRatio", "screenWindowCenter", "screenWindowWidth"};
  for (const auto& [key, value] : options.attributes)
    if (key.empty() || key.size() > 255 || key.find('\0') != std::string::npos ||
        std::find(std::begin(kWritten), std::end(kWritten), key) != std::end(kWritten))
      return std::nullopt;
  std::string out =
      plain_header(names, order, options, compression, half, image.width, image.height);
  const int lines = rows_per_chunk(compression);
  const int chunks = (image.height + lines - 1) / lines;
  const std::size_t row_bytes = std::size_t(image.width) * names.size() * (half ? 2 : 4);
  const std::size_t table = out.size();
  out.resize(table + std::size_t(chunks) * 8);
  // Chunks are packed and compressed on their own, in parallel, each into its own bytes, and put
  // in order afterwards, so the file is the same byte for byte on any number of threads. They go
  // in batches of about kBatchBytes of samples, so that no more than a batch is held twice.
  constexpr std::size_t kBatchBytes = std::size_t(16) << 20;
  const int batch = int(std::clamp<std::size_t>(kBatchBytes / (row_bytes * std::size_t(lines) + 1),
                                                1, std::size_t(chunks)));
  std::vector<std::string> pieces(static_cast<std::size_t>(batch));
  std::atomic<bool> failed = false;
  for (int b0 = 0; b0 < chunks && !failed; b0 += batch) {
    const int b1 = std::min(chunks, b0 + batch);
    parallel_for(b1 - b0, compression == kNone ? 8 : 1, [&](int64_t i0, int64_t i1) {
      ChunkScratch scratch(row_bytes * std::size_t(lines), compression != kNone);
      for (int64_t i = i0; i < i1; ++i) {
        const int first = (b0 + int(i)) * lines;
        if (!encode_chunk(image, first, std::min(lines, image.height - first), order, half,
                          row_bytes, scratch, pieces[std::size_t(i)])) {
          failed = true;
          return;
        }
      }
    });
    for (int k = b0; k < b1 && !failed; ++k) {
      const uint64_t offset = out.size();
      std::memcpy(out.data() + table + std::size_t(k) * 8, &offset, 8);
      out += pieces[std::size_t(k - b0)];
    }
  }
  if (failed) return std::nullopt;
  return out;
}

}  // namespace emaki::io::detail
