#include "io/png_io.h"

#include <fmt/format.h>
#include <png.h>

#include <algorithm>
#include <cctype>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/read_limits.h"

namespace emaki::io::detail {
namespace {

// ---------------------------------------------------------------------------------------------
// The libpng side. libpng reports an error by longjmp back to the last setjmp, which skips the
// destructor of every C++ object in the frames it crosses (undefined behaviour; issue 9 saw a
// truncated 30000^2 PNG leak its 1 GB image this way). So the two functions that call setjmp,
// png_start and png_read_pixels, hold only plain data and write only into raw buffers their
// caller owns; everything with a destructor (the image, the strings of an error) lives in
// decode(), which no longjmp crosses.

// Where the bytes come from: a FILE or a memory buffer.
struct PngSource {
  FILE* file = nullptr;
  const unsigned char* data = nullptr;
  std::size_t size = 0;
  std::size_t pos = 0;
};

// The message of libpng's last error, kept by on_error.
struct PngMessage {
  char text[160] = {};
};

// libpng's read state.
struct PngDecoder {
  png_structp png = nullptr;
  png_infop info = nullptr;
  PngMessage error;
};

// What png_start found: the header after the transforms decode() asks for.
struct PngHeader {
  png_uint_32 width = 0, height = 0;
  int channels = 0, bit_depth = 0, passes = 1;
  png_size_t row_bytes = 0;
};

// libpng reports through callbacks; keep its message and longjmp out, never print.
void on_error(png_structp png, png_const_charp msg) {
  auto* m = static_cast<PngMessage*>(png_get_error_ptr(png));
  std::snprintf(m->text, sizeof m->text, "%s", msg ? msg : "unknown libpng error");
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

void read_source(png_structp png, png_bytep out, png_size_t n) {
  auto* s = static_cast<PngSource*>(png_get_io_ptr(png));
  if (s->file) {
    if (std::fread(out, 1, n, s->file) != n)
      png_error(png, std::ferror(s->file) ? "read error" : "unexpected end of file");
    return;
  }
  if (n > s->size - s->pos) png_error(png, "unexpected end of file");
  std::memcpy(out, s->data + s->pos, n);
  s->pos += n;
}

// Reads the chunks up to the pixels and sets up 8/16-bit gray/RGB with optional alpha.
bool png_start(PngDecoder& d, PngSource& src, PngHeader& h) {
  if (setjmp(png_jmpbuf(d.png))) return false;
  png_set_read_fn(d.png, &src, read_source);
  // Ancillary chunks (iCCP, zTXt, sPLT, unknown ones) are held in memory; bound them whatever
  // the libpng build's defaults are.
  png_set_chunk_malloc_max(d.png, 8 << 20);
  png_set_chunk_cache_max(d.png, 1000);
  png_read_info(d.png, d.info);
  const int color = png_get_color_type(d.png, d.info);
  const int depth = png_get_bit_depth(d.png, d.info);
  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(d.png);
  if (color == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(d.png);
  if (png_get_valid(d.png, d.info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(d.png);
  if (depth == 16) png_set_swap(d.png);  // PNG is big-endian
  h.passes = png_set_interlace_handling(d.png);
  png_read_update_info(d.png, d.info);
  h.width = png_get_image_width(d.png, d.info);
  h.height = png_get_image_height(d.png, d.info);
  h.channels = png_get_channels(d.png, d.info);
  h.bit_depth = png_get_bit_depth(d.png, d.info);
  h.row_bytes = png_get_rowbytes(d.png, d.info);
  return true;
}

// Decodes every pass of every row into `pixels` (rows `stride` bytes apart), then the chunks
// after the pixels. Row by row, so no row-pointer array as tall as the image is needed.
bool png_read_pixels(PngDecoder& d, unsigned char* pixels, std::size_t stride, png_uint_32 height,
                     int passes) {
  if (setjmp(png_jmpbuf(d.png))) return false;
  for (int p = 0; p < passes; ++p)
    for (png_uint_32 y = 0; y < height; ++y) png_read_row(d.png, pixels + y * stride, nullptr);
  png_read_end(d.png, nullptr);
  return true;
}

// ---------------------------------------------------------------------------------------------
// The C++ side.

struct DecoderCloser {
  PngDecoder& d;
  ~DecoderCloser() { png_destroy_read_struct(&d.png, &d.info, nullptr); }
};

// Walks the chunk layout (length, type, data, CRC) up to IEND before libpng sees the bytes.
// libpng allocates a chunk's claimed length before reading it (a 10-byte tEXt that claims
// 1.9 GB took 1.9 GB), and a truncated file would be found short only after its whole image
// was allocated: a chunk must fit in what is left of the file, and the file must reach IEND.
void check_chunks(PngSource& src, const std::string& subject) {
  uint64_t size = src.size;
  if (src.file) {
    if (std::fseek(src.file, 0, SEEK_END) != 0) throw Error(subject, "cannot read the file");
    const long end = std::ftell(src.file);
    if (end < 0 || std::fseek(src.file, 0, SEEK_SET) != 0)
      throw Error(subject, "cannot read the file");
    size = uint64_t(end);
  }
  auto read_at = [&](uint64_t at, unsigned char* out, std::size_t n) {
    if (!src.file) return std::memcpy(out, src.data + at, n), true;
    return std::fseek(src.file, long(at), SEEK_SET) == 0 && std::fread(out, 1, n, src.file) == n;
  };
  unsigned char sig[8];
  if (size < 8 || !read_at(0, sig, 8) || png_sig_cmp(sig, 0, 8) != 0)
    throw Error(subject, "not a PNG file");
  uint64_t pos = 8;
  for (;;) {
    unsigned char head[8];
    if (pos + 12 > size || !read_at(pos, head, 8))
      throw Error(subject, "corrupt or truncated PNG (the file ends before its IEND chunk)");
    const uint64_t length = uint64_t(head[0]) << 24 | uint64_t(head[1]) << 16 |
                            uint64_t(head[2]) << 8 | uint64_t(head[3]);
    std::string type;
    for (int i = 4; i < 8; ++i) type += std::isalpha(head[i]) ? char(head[i]) : '?';
    if (length > PNG_UINT_31_MAX || length > size - pos - 12)
      throw Error(subject, "corrupt or truncated PNG (chunk '" + type + "' claims " +
                               std::to_string(length) + " bytes, past the end of the file)");
    pos += 12 + length;
    if (type == "IEND") break;
  }
  if (src.file && std::fseek(src.file, 0, SEEK_SET) != 0)
    throw Error(subject, "cannot read the file");
}

template <typename T>
Image<T> read_pixels(PngDecoder& d, const PngHeader& h, const std::string& subject) {
  Image<T> im = allocate_image<T>(subject, int(h.width), int(h.height), h.channels);
  if (!png_read_pixels(d, reinterpret_cast<unsigned char*>(im.row(0)),
                       std::size_t(im.stride()) * sizeof(T), h.height, h.passes))
    throw Error(subject, std::string("corrupt or truncated PNG (") + d.error.text + ")");
  return im;
}

AnyImage decode(PngSource& src, const std::string& subject, bool header_only) {
  check_chunks(src, subject);
  PngDecoder d;
  d.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &d.error, on_error, on_warning);
  d.info = d.png ? png_create_info_struct(d.png) : nullptr;
  DecoderCloser closer{d};
  if (!d.png || !d.info) throw Error(subject, "out of memory reading PNG");
  PngHeader h;
  if (!png_start(d, src, h))
    throw Error(subject, std::string("corrupt or truncated PNG (") + d.error.text + ")");
  // libpng has checked the IHDR against PNG's own limits (31-bit sizes, at most 10^6 a side);
  // the budget is ours, and holds before any pixel memory exists.
  if (h.channels < 1 || h.channels > 4 || (h.bit_depth != 8 && h.bit_depth != 16))
    throw Error(subject, "unsupported PNG layout (" + std::to_string(h.channels) + " channels of " +
                             std::to_string(h.bit_depth) + " bits)");
  const int bytes_per_sample = h.bit_depth / 8;
  if (bytes_per_sample == 2)
    check_image_alloc<uint16_t>(subject, h.width, h.height, h.channels);
  else
    check_image_alloc<uint8_t>(subject, h.width, h.height, h.channels);
  // libpng writes png_get_rowbytes() bytes a row: it must be exactly the image's row, or a row
  // would overrun the one below (and the last one the buffer).
  std::optional<int64_t> row = checked_mul<int64_t>(h.width, h.channels);
  if (row) row = checked_mul<int64_t>(*row, bytes_per_sample);
  if (!row || uint64_t(*row) != uint64_t(h.row_bytes))
    throw Error(subject, "PNG row size does not match its header");
  AnyImage result;
  static const char* kNames[4][4] = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  for (int c = 0; c < h.channels; ++c) result.channel_names.push_back(kNames[h.channels - 1][c]);
  if (header_only) return result;
  if (bytes_per_sample == 2)
    result.image = read_pixels<uint16_t>(d, h, subject);
  else
    result.image = read_pixels<uint8_t>(d, h, subject);
  return result;
}

}  // namespace

AnyImage read_png(const std::string& path) {
  std::unique_ptr<FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw Error(path, "cannot open for reading");
  PngSource src;
  src.file = file.get();
  return decode(src, path, false);
}

AnyImage read_png(std::FILE* file, const std::string& name) {
  PngSource src;
  src.file = file;
  return decode(src, name, false);
}

AnyImage read_png_header(const std::string& path) {
  std::unique_ptr<FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw Error(path, "cannot open for reading");
  PngSource src;
  src.file = file.get();
  return decode(src, path, true);
}

void check_png_complete(const std::string& path, uint64_t size, const std::string& subject) {
  std::unique_ptr<FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw Error(subject, "cannot open for reading");
  PngSource src;
  src.file = file.get();
  decode(src, subject, true);
  // The empty IEND chunk: its length, its type and its CRC.
  static const unsigned char kEnd[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  unsigned char end[12] = {};
  if (std::fseek(file.get(), 0, SEEK_END) != 0) throw Error(subject, "cannot read the file");
  const long have = std::ftell(file.get());
  if (have < 0 || (size != 0 && uint64_t(have) != size))
    throw Error(subject, fmt::format("holds {} bytes, {} were written (disk full?)", have, size));
  if (std::fseek(file.get(), -12, SEEK_END) != 0 || std::fread(end, 1, 12, file.get()) != 12 ||
      !std::equal(end, end + 12, kEnd))
    throw Error(subject, "PNG has no end chunk (the file is truncated)");
}

AnyImage read_png_memory(const void* data, std::size_t size, const std::string& name) {
  PngSource src;
  src.data = static_cast<const unsigned char*>(data);
  src.size = size;
  return decode(src, name, false);
}

}  // namespace emaki::io::detail
