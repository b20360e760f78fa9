#include "io/exr_header.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/read_limits.h"

namespace emaki::io::detail {
namespace {

// The header is read through one of two sources that know the file's size, so that every
// length the header claims can be held against what is left of the file.
class Source {
 public:
  explicit Source(uint64_t size) : size_(size) {}
  virtual ~Source() = default;
  uint64_t left() const { return size_ - pos_; }
  uint64_t size() const { return size_; }
  // False when fewer than n bytes are left.
  bool read(void* out, uint64_t n) {
    if (n > left() || !read_raw(out, n)) return false;
    pos_ += n;
    return true;
  }
  bool skip(uint64_t n) {
    if (n > left() || !skip_raw(n)) return false;
    pos_ += n;
    return true;
  }
  uint64_t position() const { return pos_; }
  // Reads n bytes at `offset` (false past the end); the sequential position is lost after it.
  bool read_at(uint64_t offset, void* out, uint64_t n) {
    if (offset > size_ || n > size_ - offset || !read_at_raw(offset, out, n)) return false;
    pos_ = offset + n;
    return true;
  }

 private:
  virtual bool read_raw(void* out, uint64_t n) = 0;
  virtual bool skip_raw(uint64_t n) = 0;
  virtual bool read_at_raw(uint64_t offset, void* out, uint64_t n) = 0;
  uint64_t size_;
  uint64_t pos_ = 0;
};

class MemorySource final : public Source {
 public:
  MemorySource(const unsigned char* data, std::size_t size) : Source(size), data_(data) {}

 private:
  bool read_raw(void* out, uint64_t n) override {
    std::memcpy(out, data_ + at_, n);
    at_ += n;
    return true;
  }
  bool skip_raw(uint64_t n) override {
    at_ += n;
    return true;
  }
  bool read_at_raw(uint64_t offset, void* out, uint64_t n) override {
    std::memcpy(out, data_ + offset, n);
    at_ = offset + n;
    return true;
  }
  const unsigned char* data_;
  uint64_t at_ = 0;
};

class FileSource final : public Source {
 public:
  FileSource(std::FILE* f, uint64_t size) : Source(size), f_(f) {}

 private:
  bool read_raw(void* out, uint64_t n) override { return std::fread(out, 1, n, f_) == n; }
  bool skip_raw(uint64_t n) override {
    return n <= uint64_t(std::numeric_limits<long>::max()) &&
           std::fseek(f_, long(n), SEEK_CUR) == 0;
  }
  bool read_at_raw(uint64_t offset, void* out, uint64_t n) override {
    return offset <= uint64_t(std::numeric_limits<long>::max()) &&
           std::fseek(f_, long(offset), SEEK_SET) == 0 && std::fread(out, 1, n, f_) == n;
  }
  std::FILE* f_;
};

// OpenEXR's version field: the format version in the low byte, then flags.
constexpr uint32_t kTiledFlag = 0x200;
constexpr uint32_t kNonImageFlag = 0x800;  // deep data
constexpr uint32_t kMultipartFlag = 0x1000;
// OpenEXR names are at most 255 bytes (31 without the long-names flag; we take the larger).
constexpr std::size_t kMaxName = 255;
// A channel list entry: a name, its NUL, pixel type, pLinear + 3 reserved bytes, x and y
// sampling.
constexpr int64_t kChannelEntryMax = kMaxName + 1 + 16;
// A chunk may be this large whatever the image size (tiles of 64x64 on a 10x10 image, or a
// 256-scanline DWAB block of a short image, are ordinary).
constexpr int64_t kChunkBytesFloor = int64_t(16) << 20;

struct Part {
  std::optional<std::array<int32_t, 4>> data_window, display_window;
  bool has_channels = false;
  int channels = 0;
  int64_t pixel_bytes = 0;
  int compression = -1;
  bool has_tiles = false;
  uint32_t tile_x = 0, tile_y = 0;
  std::string type;
  std::optional<int32_t> chunk_count;
};

class Walker {
 public:
  Walker(Source& in, const std::string& subject) : in_(in), subject_(subject) {}

  // The headers, then (`chunks`) the offset tables and every chunk they point at.
  void run(bool chunks) {
    headers();
    if (chunks) check_chunks();
  }

 private:
  struct PartChunks {
    uint64_t count = 0;
    bool tiled = false;
  };

  void headers() {
    unsigned char magic[4];
    if (!in_.read(magic, 4) || !has_exr_magic(magic, 4)) fail("not an OpenEXR file");
    const uint32_t version = u32();
    if ((version & 0xff) != 2)
      fail("unsupported OpenEXR version " + std::to_string(version & 0xff));
    if (version & kNonImageFlag) fail("deep (multi-sample) images are not supported");
    const bool multipart = version & kMultipartFlag;
    const bool tiled = version & kTiledFlag;
    int parts = 0;
    uint64_t chunks = 0;
    for (;;) {
      Part p;
      int attributes = 0;
      for (std::string name; !(name = cstring("attribute name")).empty(); ++attributes)
        attribute(name, p);
      if (attributes == 0) {
        // In a multipart file an empty header ends the list of headers.
        if (multipart && parts > 0) break;
        fail("header has no attributes");
      }
      if (++parts > kMaxParts)
        fail("more than " + std::to_string(kMaxParts) + " parts (subimages)");
      const bool part_tiled = multipart ? p.type == "tiledimage" : tiled;
      const uint64_t n = check_part(p, part_tiled, parts - 1);
      chunks += n;
      // The table is as long as the part's chunkCount when it has one (multipart files do).
      parts_.push_back({p.chunk_count ? uint64_t(*p.chunk_count) : n, part_tiled});
      if (!multipart) break;
    }
    multipart_ = multipart;
    // Each chunk has an 8-byte entry in the offset tables that follow the headers; OpenEXR
    // allocates those tables from the header before reading them.
    if (chunks > in_.size() / 8)
      fail("the header describes " + std::to_string(chunks) +
           " chunks, more than the file can hold offsets for (the file is truncated or corrupt)");
  }

  // The offset tables that follow the headers: every offset must point past them into the file,
  // and the chunk that starts last must end within it. A write cut short (a full disk) ends the
  // file early, so the last chunk is the one it cuts; OpenEXR writes the tables last, and a file
  // whose tables were never written holds zeros there. (A tiled part's mipmap levels are not
  // counted: their entries, further on, are not checked.)
  void check_chunks() {
    const uint64_t tables = in_.position();
    uint64_t total = 0;
    for (const PartChunks& p : parts_) total += p.count;  // each <= size / 8: no overflow
    if (total > in_.size() / 8 || tables + 8 * total > in_.size())
      fail("the file ends inside its chunk offset table (the file is truncated)");
    const uint64_t data_start = tables + 8 * total;
    uint64_t last = 0, last_prefix = 0;
    for (std::size_t part = 0; part < parts_.size(); ++part) {
      // Before a chunk's byte count: its part number (multipart), its y or its tile coordinates.
      const uint64_t prefix = (multipart_ ? 4 : 0) + (parts_[part].tiled ? 16 : 4);
      for (uint64_t c = 0; c < parts_[part].count; ++c) {
        unsigned char b[8];
        if (!in_.read(b, 8)) fail("cannot read the chunk offset table");
        uint64_t offset = 0;
        for (int k = 7; k >= 0; --k) offset = offset << 8 | b[k];
        if (offset < data_start || offset >= in_.size())
          fail(
              fmt::format("chunk {}{} is at byte {}, outside the file's {} bytes of data (the "
                          "file is truncated)",
                          c, part > 0 ? fmt::format(" of part {}", part) : "", offset, in_.size()));
        if (offset >= last) last = offset, last_prefix = prefix;
      }
    }
    if (total == 0) return;
    unsigned char n[4];
    if (last > in_.size() - last_prefix || !in_.read_at(last + last_prefix, n, 4))
      fail("the last chunk is cut short (the file is truncated)");
    const int32_t bytes =
        int32_t(uint32_t(n[0]) | uint32_t(n[1]) << 8 | uint32_t(n[2]) << 16 | uint32_t(n[3]) << 24);
    if (bytes < 0 || uint64_t(bytes) > in_.size() - (last + last_prefix + 4))
      fail("the last chunk ends past the end of the file (the file is truncated)");
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(subject_, "EXR header: " + message);
  }

  uint32_t u32() {
    unsigned char b[4];
    if (!in_.read(b, 4)) fail("ends inside the header");
    return uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  }
  int32_t i32() { return int32_t(u32()); }

  std::string cstring(const char* what) {
    std::string s;
    for (;;) {
      char c;
      if (!in_.read(&c, 1)) fail("ends inside the header");
      if (c == '\0') return s;
      if (s.size() == kMaxName)
        fail(std::string(what) + " '" + echo(s) + "' is longer than 255 bytes");
      s += c;
    }
  }

  void expect(const std::string& name, const std::string& type, int32_t size, const char* want_type,
              int32_t want_size) const {
    if (type != want_type || size != want_size)
      fail("attribute '" + name + "' is not a " + want_type);
  }

  // The value size of OpenEXR's fixed-size attribute types (0: a variable or unknown type).
  // OpenEXR reads these by their type, whatever size the header gives them, so a wrong size
  // sends it on a different walk from this one (it read a 1.7 GB attribute size from inside
  // the next one; found by fuzz_exr, tests/data/hostile/exr/box2i_of_0_bytes.exr).
  static int32_t fixed_size(const std::string& type) {
    static const std::pair<const char*, int32_t> kSizes[] = {
        {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
        {"compression", 1}, {"double", 8},   {"envmap", 1},
        {"float", 4},       {"int", 4},      {"keycode", 28},
        {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
        {"m44f", 64},       {"m44d", 128},   {"rational", 8},
        {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
        {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
        {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
    for (const auto& [t, n] : kSizes)
      if (type == t) return n;
    return 0;
  }

  void attribute(const std::string& name, Part& p) {
    const std::string type = cstring("attribute type");
    const int32_t size = i32();
    if (size < 0 || uint64_t(size) > in_.left())
      fail("attribute '" + echo(name) + "' claims " + std::to_string(size) +
           " bytes, past the end of the file");
    if (const int32_t want = fixed_size(type); want > 0 && size != want)
      fail("attribute '" + echo(name) + "' of type " + type + " has " + std::to_string(size) +
           " bytes, not " + std::to_string(want));
    if (name == "dataWindow" || name == "displayWindow") {
      expect(name, type, size, "box2i", 16);
      std::array<int32_t, 4> box;
      for (auto& v : box) v = i32();
      (name == "dataWindow" ? p.data_window : p.display_window) = box;
    } else if (name == "channels") {
      if (type != "chlist") fail("attribute 'channels' is not a chlist");
      channel_list(size, p);
    } else if (name == "compression") {
      expect(name, type, size, "compression", 1);
      unsigned char c;
      if (!in_.read(&c, 1)) fail("ends inside the header");
      p.compression = c;
    } else if (name == "tiles") {
      expect(name, type, size, "tiledesc", 9);
      p.has_tiles = true;
      p.tile_x = u32();
      p.tile_y = u32();
      if (!in_.skip(1)) fail("ends inside the header");
    } else if (name == "chunkCount") {
      expect(name, type, size, "int", 4);
      p.chunk_count = i32();
    } else if (name == "type" && type == "string" && size <= 64) {
      p.type.resize(size_t(size));
      if (!in_.read(p.type.data(), uint64_t(size))) fail("ends inside the header");
    } else if (type == "preview") {
      // OpenEXR allocates width x height RGBA8 from the first 8 bytes.
      if (size < 8) fail("attribute '" + echo(name) + "' is too short for a preview");
      const uint64_t w = u32(), h = u32();
      const auto bytes = checked_mul<uint64_t>(w * h, 4);  // w, h < 2^32: w * h fits
      if (!bytes || *bytes != uint64_t(size) - 8)
        fail("preview '" + echo(name) + "' of " + std::to_string(w) + "x" + std::to_string(h) +
             " does not match its attribute size");
      skip(uint64_t(size) - 8);
    } else if (type == "stringvector") {
      // Each string's length is allocated as read: it must lie within the attribute.
      uint64_t left = uint64_t(size);
      while (left > 0) {
        if (left < 4) fail("attribute '" + echo(name) + "' is a malformed string vector");
        const int32_t n = i32();
        left -= 4;
        if (n < 0 || uint64_t(n) > left)
          fail("attribute '" + echo(name) + "' is a malformed string vector");
        skip(uint64_t(n));
        left -= uint64_t(n);
      }
    } else {
      skip(uint64_t(size));
    }
  }

  void skip(uint64_t n) {
    if (!in_.skip(n)) fail("ends inside the header");
  }

  void channel_list(int32_t size, Part& p) {
    if (size > kMaxChannels * kChannelEntryMax + 1)
      fail("channel list is longer than " + std::to_string(kMaxChannels) + " channels can be");
    std::string buf(size_t(size), '\0');
    if (!in_.read(buf.data(), uint64_t(size))) fail("ends inside the header");
    p.has_channels = true;
    std::size_t at = 0;
    for (;;) {
      const std::size_t end = buf.find('\0', at);
      if (end == std::string::npos) fail("channel list is not terminated");
      if (end == at) {  // the empty name that ends the list, which OpenEXR reads up to
        if (end + 1 != buf.size()) fail("channel list does not fill its attribute");
        break;
      }
      if (end - at > kMaxName) fail("channel name longer than 255 bytes");
      if (buf.size() - (end + 1) < 16) fail("channel list is truncated");
      int32_t fields[4];
      std::memcpy(fields, buf.data() + end + 1, 16);  // type, pLinear+reserved, xs, ys (LE)
      const int32_t pixel_type = fields[0];
      if (pixel_type < 0 || pixel_type > 2)
        fail("channel '" + echo(buf.substr(at, end - at)) + "' has unknown pixel type " +
             std::to_string(pixel_type));
      if (fields[2] < 1 || fields[3] < 1)
        fail("channel '" + echo(buf.substr(at, end - at)) + "' has a sampling rate below 1");
      if (++p.channels > kMaxChannels)
        fail("more than " + std::to_string(kMaxChannels) + " channels (emaki reads 1 to " +
             std::to_string(kMaxChannels) + ")");
      p.pixel_bytes += pixel_type == 1 ? 2 : 4;
      at = end + 1 + 16;
    }
  }

  // Checks one part's windows, channels and chunk layout; returns its number of chunks.
  uint64_t check_part(const Part& p, bool tiled, int index) {
    const std::string part = index > 0 ? " in part " + std::to_string(index) : "";
    if (!p.data_window) fail("no data window" + part);
    if (!p.display_window) fail("no display window" + part);
    if (!p.has_channels || p.channels == 0) fail("no channels" + part);
    if (p.compression < 0) fail("no compression" + part);
    if (p.type == "deepscanline" || p.type == "deeptile")
      fail("deep (multi-sample) images are not supported");
    // x and y extents; OpenImageIO keeps origin + size in an int, so the end must be one too.
    auto extent = [&](const std::array<int32_t, 4>& b, const char* what) {
      const int64_t w = int64_t(b[2]) - b[0] + 1, h = int64_t(b[3]) - b[1] + 1;
      if (w <= 0 || h <= 0 || b[2] == std::numeric_limits<int32_t>::max() ||
          b[3] == std::numeric_limits<int32_t>::max())
        fail(std::string(what) + part + " (" + std::to_string(b[0]) + ", " + std::to_string(b[1]) +
             ") - (" + std::to_string(b[2]) + ", " + std::to_string(b[3]) +
             ") is empty or overflows");
      return std::pair<int64_t, int64_t>{w, h};
    };
    const auto [w, h] = extent(*p.data_window, "data window");
    extent(*p.display_window, "display window");
    check_pixel_budget(subject_, w, h);
    // Scanlines per chunk for each OpenEXR compression (NONE, RLE, ZIPS, ZIP, PIZ, PXR24, B44,
    // B44A, DWAA, DWAB).
    static const int kLines[10] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    if (p.compression > 9) fail("unknown compression " + std::to_string(p.compression) + part);
    int64_t chunk_w = w, chunk_h = kLines[p.compression];
    if (tiled) {
      if (!p.has_tiles) fail("tiled part has no tile description" + part);
      if (p.tile_x < 1 || p.tile_y < 1 || p.tile_x > uint32_t(std::numeric_limits<int>::max()) ||
          p.tile_y > uint32_t(std::numeric_limits<int>::max()))
        fail("tile size " + std::to_string(p.tile_x) + "x" + std::to_string(p.tile_y) + part +
             " is out of range");
      chunk_w = p.tile_x;
      chunk_h = p.tile_y;
    }
    // OpenEXR keeps a buffer per thread as large as one chunk: a chunk far larger than the whole
    // image is a hostile header, not a layout.
    const auto chunk_bytes = checked_mul<int64_t>(chunk_w * chunk_h, p.pixel_bytes);
    const auto image_bytes = checked_mul<int64_t>(w * h, p.pixel_bytes);  // w * h: budgeted
    const int64_t allowed = image_bytes ? std::max(kChunkBytesFloor, *image_bytes)
                                        : std::numeric_limits<int64_t>::max();
    if (!chunk_bytes || *chunk_bytes > allowed)
      fail((tiled
                ? "tiles of " + std::to_string(chunk_w) + "x" + std::to_string(chunk_h)
                : "scanline blocks of " + std::to_string(chunk_w) + "x" + std::to_string(chunk_h)) +
           part + " are larger than the " + std::to_string(w) + "x" + std::to_string(h) + " image");
    if (p.chunk_count && (*p.chunk_count < 0 || uint64_t(*p.chunk_count) > in_.size() / 8))
      fail("chunk count " + std::to_string(*p.chunk_count) + part +
           " is more than the file can hold");
    return uint64_t((w + chunk_w - 1) / chunk_w) * uint64_t((h + chunk_h - 1) / chunk_h);
  }

  Source& in_;
  const std::string& subject_;
  std::vector<PartChunks> parts_;
  bool multipart_ = false;
};

}  // namespace

bool has_exr_magic(const unsigned char* bytes, std::size_t n) {
  static const unsigned char kMagic[4] = {0x76, 0x2f, 0x31, 0x01};
  return n >= 4 && std::equal(bytes, bytes + 4, kMagic);
}

void check_exr_header(const unsigned char* data, std::size_t size, const std::string& subject) {
  MemorySource in(data, size);
  Walker(in, subject).run(false);
}

namespace {

void walk_file(std::FILE* file, const std::string& subject, bool chunks) {
  if (std::fseek(file, 0, SEEK_END) != 0) throw Error(subject, "cannot read the file");
  const long size = std::ftell(file);
  if (size < 0 || std::fseek(file, 0, SEEK_SET) != 0) throw Error(subject, "cannot read the file");
  FileSource in(file, uint64_t(size));
  Walker(in, subject).run(chunks);
}

}  // namespace

void check_exr_header(std::FILE* file, const std::string& subject) {
  walk_file(file, subject, false);
}

void check_exr_complete(const unsigned char* data, std::size_t size, const std::string& subject) {
  MemorySource in(data, size);
  Walker(in, subject).run(true);
}

void check_exr_complete(std::FILE* file, const std::string& subject) {
  walk_file(file, subject, true);
}

}  // namespace emaki::io::detail
