#include "io/png_io.h"

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <memory>
#include <vector>

#include "core/error.h"

namespace emaki::io::detail {
namespace {

struct PngError {
  std::string message;
};

// libpng reports through callbacks; keep its message and longjmp out, never print.
void on_error(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngError*>(png_get_error_ptr(png));
  e->message = msg ? msg : "unknown libpng error";
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

struct FileCloser {
  void operator()(FILE* f) const {
    if (f) std::fclose(f);
  }
};

}  // namespace

AnyImage read_png(const std::string& path) {
  std::unique_ptr<FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw Error(path, "cannot open for reading");
  PngError err;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) throw Error(path, "out of memory reading PNG");
  // Everything libpng-owned is released on both paths; these live outside the setjmp scope.
  std::vector<png_bytep> rows;
  AnyImage result;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(path, "corrupt or truncated PNG (" + err.message + ")");
  }
  png_init_io(png, file.get());
  png_read_info(png, info);
  const int color = png_get_color_type(png, info);
  int depth = png_get_bit_depth(png, info);
  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  if (depth == 16) png_set_swap(png);  // PNG is big-endian
  png_read_update_info(png, info);
  const int w = int(png_get_image_width(png, info)), h = int(png_get_image_height(png, info));
  const int channels = png_get_channels(png, info);
  depth = png_get_bit_depth(png, info);
  if (w <= 0 || h <= 0) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw Error(path, "image has no pixels");
  }
  rows.resize(h);
  if (depth == 16) {
    Image<uint16_t> im(w, h, channels);
    for (int y = 0; y < h; ++y) rows[y] = reinterpret_cast<png_bytep>(im.row(y));
    png_read_image(png, rows.data());
    result.image = std::move(im);
  } else {
    Image<uint8_t> im(w, h, channels);
    for (int y = 0; y < h; ++y) rows[y] = im.row(y);
    png_read_image(png, rows.data());
    result.image = std::move(im);
  }
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  static const char* kNames[4][4] = {{"Y"}, {"Y", "A"}, {"R", "G", "B"}, {"R", "G", "B", "A"}};
  for (int c = 0; c < channels; ++c) result.channel_names.push_back(kNames[channels - 1][c]);
  return result;
}

void write_png(const std::string& path, ImageView<const float> image, bool sixteen_bit,
               const std::string& subject) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw Error(subject, "cannot open for writing");
  write_png(file, image, sixteen_bit, subject);
}

void write_png(std::FILE* opened, ImageView<const float> image, bool sixteen_bit,
               const std::string& subject) {
  std::unique_ptr<FILE, FileCloser> file(opened);
  if (image.channels < 1 || image.channels > 4) throw Error(subject, "PNG takes 1 to 4 channels");
  const int w = image.width, h = image.height, nc = image.channels;
  const int bytes = sixteen_bit ? 2 : 1;
  std::vector<unsigned char> buf(std::size_t(w) * h * nc * bytes);
  for (int y = 0; y < h; ++y) {
    const float* r = image.row(y);
    for (int i = 0; i < w * nc; ++i) {
      const float v = std::clamp(r[i], 0.0f, 1.0f);
      const std::size_t o = (std::size_t(y) * w * nc + i) * bytes;
      if (sixteen_bit) {
        const unsigned q = unsigned(v * 65535.0f + 0.5f);
        buf[o] = (unsigned char)(q >> 8);  // big-endian
        buf[o + 1] = (unsigned char)(q & 255);
      } else {
        buf[o] = (unsigned char)(v * 255.0f + 0.5f);
      }
    }
  }
  PngError err;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &err, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) throw Error(subject, "out of memory writing PNG");
  std::vector<png_bytep> rows(h);
  for (int y = 0; y < h; ++y) rows[y] = buf.data() + std::size_t(y) * w * nc * bytes;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw Error(subject, "write failed (" + err.message + ")");
  }
  static const int kColor[4] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                PNG_COLOR_TYPE_RGB_ALPHA};
  png_init_io(png, file.get());
  png_set_IHDR(png, info, w, h, sixteen_bit ? 16 : 8, kColor[nc - 1], PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(file.get()) != 0) throw Error(subject, "write failed (disk full?)");
}

}  // namespace emaki::io::detail
