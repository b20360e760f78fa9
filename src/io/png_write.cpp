// PNG writing. libpng's writer deflates the whole image as one zlib stream on one thread (level
// 6, five filters tried per row): on a 2048^2 synthesis that was 0.75 s of the command's 7.9 s,
// after the engine had finished. Here the rows are cut into strips whose height depends only on
// the row size, never on the thread count, and each strip is filtered and deflated on its own, in
// parallel; the strips' raw deflate streams end on a byte boundary (Z_SYNC_FLUSH) and follow one
// another in a single zlib stream, whose Adler-32 is combined from the strips'. The bytes are
// therefore the same for any thread count. zlib's run-length strategy only looks one byte back,
// so a strip loses nothing by not seeing the one before it. Measured with `emaki synth` (wall
// time outside reading and synthesis, two threads; docs/design/engine-speed.md): 2048^2 0.74-0.77 s
// -> 0.08 s, StyLit 1200x912 0.13-0.16 s -> 0.03-0.05 s; the files are 2 % smaller to 4 % larger.
#include <pnglibconf.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "core/parallel.h"
#include "io/png_io.h"

namespace emaki::io::detail {
namespace {

// Raw bytes per strip (about): enough rows that deflate's per-strip start costs little, few
// enough that a 1080p frame makes dozens of strips for the threads to share.
constexpr std::size_t kStripBytes = std::size_t(1) << 18;

constexpr int kMaxSide = PNG_USER_WIDTH_MAX;
static_assert(PNG_USER_WIDTH_MAX == PNG_USER_HEIGHT_MAX && PNG_USER_WIDTH_MAX <= 1000000);

void put_u32(std::vector<unsigned char>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back((unsigned char)(v >> s));
}

// The samples of row y as PNG stores them (8-bit, or 16-bit big-endian).
void row_bytes(ImageView<const float> image, int y, bool sixteen_bit, unsigned char* out) {
  const float* r = image.row(y);
  const int n = image.width * image.channels;
  if (sixteen_bit) {
    for (int i = 0; i < n; ++i) {
      const unsigned q = to_u16(r[i]);
      out[2 * i] = (unsigned char)(q >> 8);
      out[2 * i + 1] = (unsigned char)(q & 255);
    }
  } else {
    for (int i = 0; i < n; ++i) out[i] = to_u8(r[i]);
  }
}

int paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
}

// Filters `cur` (previous row `prev`, all zeros above the first) into out[0] (the filter type)
// and out[1..n]: of the five filters, the one whose bytes, read as signed, have the smallest
// sum of magnitudes (the heuristic the PNG specification recommends, and libpng's default).
void filter_row(const unsigned char* prev, const unsigned char* cur, int n, int bpp,
                std::array<std::vector<unsigned char>, 4>& scratch, unsigned char* out) {
  unsigned char* sub = scratch[0].data();
  unsigned char* up = scratch[1].data();
  unsigned char* avg = scratch[2].data();
  unsigned char* pae = scratch[3].data();
  for (int i = 0; i < n; ++i) {
    const int a = i >= bpp ? cur[i - bpp] : 0, b = prev[i], c = i >= bpp ? prev[i - bpp] : 0;
    sub[i] = (unsigned char)(cur[i] - a);
    up[i] = (unsigned char)(cur[i] - b);
    avg[i] = (unsigned char)(cur[i] - (a + b) / 2);
    pae[i] = (unsigned char)(cur[i] - paeth(a, b, c));
  }
  // Filter type f's bytes: the row itself for 0 (none), else scratch[f - 1].
  const unsigned char* filtered[5] = {cur, sub, up, avg, pae};
  long best_sum = -1;
  int best = 0;
  for (int f = 0; f < 5; ++f) {
    long sum = 0;
    for (int i = 0; i < n; ++i) sum += filtered[f][i] < 128 ? filtered[f][i] : 256 - filtered[f][i];
    if (best_sum < 0 || sum < best_sum) best_sum = sum, best = f;
  }
  out[0] = (unsigned char)best;
  std::copy(filtered[best], filtered[best] + n, out + 1);
}

// One strip: rows [y0, y1) filtered and deflated. `last` ends the deflate stream.
struct Strip {
  std::vector<unsigned char> deflated;
  uLong adler = 1;
  std::size_t raw_size = 0;
};

Strip encode_strip(ImageView<const float> image, bool sixteen_bit, int y0, int y1, bool last,
                   const std::string& subject) {
  const int n = image.width * image.channels * (sixteen_bit ? 2 : 1);
  const int bpp = image.channels * (sixteen_bit ? 2 : 1);
  std::vector<unsigned char> prev(n, 0), cur(n);
  if (y0 > 0) row_bytes(image, y0 - 1, sixteen_bit, prev.data());
  std::array<std::vector<unsigned char>, 4> scratch;
  for (auto& s : scratch) s.resize(n);
  Strip s;
  s.raw_size = std::size_t(y1 - y0) * (n + 1);
  std::vector<unsigned char> filtered(s.raw_size);
  for (int y = y0; y < y1; ++y) {
    row_bytes(image, y, sixteen_bit, cur.data());
    filter_row(prev.data(), cur.data(), n, bpp, scratch,
               filtered.data() + std::size_t(y - y0) * (n + 1));
    prev.swap(cur);
  }
  s.adler = adler32_z(1, filtered.data(), filtered.size());
  z_stream z{};
  // Raw deflate (no zlib header: the stream's one header is written before the first strip).
  if (deflateInit2(&z, 1, Z_DEFLATED, -15, 8, Z_RLE) != Z_OK)
    throw Error(subject, "out of memory writing PNG");
  s.deflated.resize(deflateBound(&z, uLong(filtered.size())) + 16);
  z.next_in = filtered.data();
  z.avail_in = uInt(filtered.size());
  z.next_out = s.deflated.data();
  z.avail_out = uInt(s.deflated.size());
  const int ret = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
  const bool ok = last ? ret == Z_STREAM_END : ret == Z_OK && z.avail_in == 0;
  s.deflated.resize(s.deflated.size() - z.avail_out);
  deflateEnd(&z);
  if (!ok) throw Error(subject, "PNG compression failed");
  return s;
}

void write_chunk(std::FILE* f, const char type[4], const unsigned char* data, std::size_t size,
                 const std::string& subject) {
  std::vector<unsigned char> head;
  put_u32(head, uint32_t(size));
  head.insert(head.end(), type, type + 4);
  uLong crc = crc32_z(0, reinterpret_cast<const unsigned char*>(type), 4);
  if (size > 0) crc = crc32_z(crc, data, size);  // (a null buffer would reset the CRC)
  std::vector<unsigned char> tail;
  put_u32(tail, uint32_t(crc));
  if (std::fwrite(head.data(), 1, head.size(), f) != head.size() ||
      (size > 0 && std::fwrite(data, 1, size, f) != size) ||
      std::fwrite(tail.data(), 1, tail.size(), f) != tail.size())
    throw Error(subject, "write failed (disk full?)");
}

}  // namespace

uint64_t write_png(const std::string& path, ImageView<const float> image, bool sixteen_bit,
                   const std::string& subject) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw Error(subject, "cannot open for writing");
  return write_png(file, image, sixteen_bit, subject);
}

uint64_t write_png(std::FILE* opened, ImageView<const float> image, bool sixteen_bit,
                   const std::string& subject) {
  std::unique_ptr<FILE, FileCloser> file(opened);
  if (image.channels < 1 || image.channels > 4) throw Error(subject, "PNG takes 1 to 4 channels");
  if (image.width < 1 || image.height < 1) throw Error(subject, "PNG needs at least one pixel");
  // libpng's own limit, which emaki's reader keeps: a wider or taller file could not be read
  // back. It also bounds a strip (8 MB a row at most) well below zlib's and PNG's 32-bit sizes.
  if (image.width > kMaxSide || image.height > kMaxSide)
    throw Error(subject, "PNG sides are limited to " + std::to_string(kMaxSide) + " pixels");
  const int w = image.width, h = image.height;
  const std::size_t row = std::size_t(w) * image.channels * (sixteen_bit ? 2 : 1) + 1;
  const int strip_rows = int(std::max<std::size_t>(1, kStripBytes / row));
  const int strips = (h + strip_rows - 1) / strip_rows;
  std::vector<Strip> parts(strips);
  parallel_for(strips, 1, [&](int64_t s0, int64_t s1) {
    for (int64_t s = s0; s < s1; ++s) {
      const int y0 = int(s) * strip_rows;
      parts[s] = encode_strip(image, sixteen_bit, y0, std::min(h, y0 + strip_rows), s == strips - 1,
                              subject);
    }
  });

  static const unsigned char kSignature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  if (std::fwrite(kSignature, 1, 8, file.get()) != 8)
    throw Error(subject, "write failed (disk full?)");
  static const unsigned char kColor[4] = {0, 4, 2, 6};  // gray, gray + alpha, RGB, RGBA
  std::vector<unsigned char> ihdr;
  put_u32(ihdr, uint32_t(w));
  put_u32(ihdr, uint32_t(h));
  ihdr.insert(ihdr.end(), {(unsigned char)(sixteen_bit ? 16 : 8), kColor[image.channels - 1], 0, 0,
                           0});  // deflate, adaptive filtering, no interlace
  write_chunk(file.get(), "IHDR", ihdr.data(), ihdr.size(), subject);
  // One zlib stream over the strips: its header (deflate, 32K window, check bits) in front,
  // the Adler-32 of all the filtered bytes behind.
  uLong adler = 1;
  for (auto& p : parts) {
    adler = adler32_combine(adler, p.adler, z_off_t(p.raw_size));
    if (&p == &parts.front()) p.deflated.insert(p.deflated.begin(), {0x78, 0x01});
    if (&p == &parts.back()) put_u32(p.deflated, uint32_t(adler));
    write_chunk(file.get(), "IDAT", p.deflated.data(), p.deflated.size(), subject);
  }
  write_chunk(file.get(), "IEND", nullptr, 0, subject);
  const long bytes = std::ftell(file.get());
  if (std::fflush(file.get()) != 0 || bytes < 0) throw Error(subject, "write failed (disk full?)");
  // A close can report what the flush did not (a network file system's deferred error).
  if (std::fclose(file.release()) != 0) throw Error(subject, "write failed on close (disk full?)");
  return uint64_t(bytes);
}

}  // namespace emaki::io::detail
