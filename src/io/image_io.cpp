#include "io/image_io.h"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>

#include "core/error.h"

namespace emaki::io {
namespace fs = std::filesystem;
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

// ---------------------------------------------------------------------------------------------
// AnyImage

int AnyImage::width() const {
  return std::visit([](const auto& im) { return im.width(); }, image);
}
int AnyImage::height() const {
  return std::visit([](const auto& im) { return im.height(); }, image);
}
int AnyImage::channels() const {
  return std::visit([](const auto& im) { return im.channels(); }, image);
}
PixelType AnyImage::type() const {
  return image.index() == 0 ? PixelType::kU8 : image.index() == 1 ? PixelType::kU16 : PixelType::kF32;
}

namespace {
template <typename T>
float normalised(T v) {
  if constexpr (std::is_same_v<T, uint8_t>) return v * (1.0f / 255.0f);
  else if constexpr (std::is_same_v<T, uint16_t>) return v * (1.0f / 65535.0f);
  else return v;
}
}  // namespace

float AnyImage::value(int x, int y, int c) const {
  return std::visit([&](const auto& im) { return normalised(im(x, y, c)); }, image);
}

Image<float> AnyImage::to_float() const {
  return std::visit(
      [](const auto& im) {
        Image<float> out(im.width(), im.height(), im.channels());
        for (int y = 0; y < im.height(); ++y) {
          const auto* s = im.row(y);
          float* d = out.row(y);
          for (int i = 0; i < im.width() * im.channels(); ++i) d[i] = normalised(s[i]);
        }
        return out;
      },
      image);
}

AnyImage AnyImage::select_channels(int first, int count) const {
  AnyImage out;
  std::visit(
      [&](const auto& im) {
        using T = std::decay_t<decltype(im(0, 0))>;
        Image<T> o(im.width(), im.height(), count);
        for (int y = 0; y < im.height(); ++y)
          for (int x = 0; x < im.width(); ++x)
            for (int c = 0; c < count; ++c) o(x, y, c) = im(x, y, first + c);
        out.image = std::move(o);
      },
      image);
  for (int c = 0; c < count && first + c < int(channel_names.size()); ++c)
    out.channel_names.push_back(channel_names[first + c]);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Reading

namespace {

std::string oiio_error(const std::string& fallback) {
  std::string e = OIIO::geterror();
  if (e.empty()) return fallback;
  // One line: keep the first line of OIIO's message.
  if (auto nl = e.find('\n'); nl != std::string::npos) e.resize(nl);
  return e;
}

std::unique_ptr<ImageInput> open_input(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path, "file not found");
  if (fs::is_directory(path, ec)) throw Error(path, "is a folder, not an image file");
  auto in = ImageInput::open(path);
  if (!in) throw Error(path, "cannot read image (" + oiio_error("unknown format") + ")");
  return in;
}

template <typename T>
void read_into(ImageInput& in, const std::string& path, int subimage, int chbegin, int chend,
               Image<T>& out, int dst_channel_offset, TypeDesc type) {
  const ImageSpec& spec = in.spec();
  const int nch = chend - chbegin;
  std::vector<T> buf(std::size_t(spec.width) * spec.height * nch);
  if (!in.read_image(subimage, 0, chbegin, chend, type, buf.data()))
    throw Error(path, "corrupt or truncated image (" + oiio_error(in.geterror()) + ")");
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x)
      for (int c = 0; c < nch; ++c)
        out(x, y, dst_channel_offset + c) = buf[(std::size_t(y) * spec.width + x) * nch + c];
}

void check_finite(const Image<float>& im, const std::string& path) {
  for (int y = 0; y < im.height(); ++y) {
    const float* r = im.row(y);
    for (int i = 0; i < im.width() * im.channels(); ++i)
      if (!std::isfinite(r[i]))
        throw Error(path, fmt::format("non-finite value (NaN or Inf) at pixel ({}, {}) channel {}",
                                      i / im.channels(), y, i % im.channels()));
  }
}

}  // namespace

std::vector<std::string> list_channels(const std::string& path) {
  auto in = open_input(path);
  std::vector<std::string> names;
  for (int sub = 0; in->seek_subimage(sub, 0); ++sub)
    for (const auto& n : in->spec().channelnames) names.push_back(n);
  return names;
}

AnyImage read_image(const std::string& path, const ReadOptions& options) {
  auto in = open_input(path);
  AnyImage result;
  if (options.channels.empty()) {
    const ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0) throw Error(path, "image has no pixels");
    const int nch = spec.nchannels;
    const TypeDesc::BASETYPE bt = TypeDesc::BASETYPE(spec.format.basetype);
    if (bt == TypeDesc::UINT8 || bt == TypeDesc::INT8) {
      Image<uint8_t> im(spec.width, spec.height, nch);
      read_into(*in, path, 0, 0, nch, im, 0, TypeDesc::UINT8);
      result.image = std::move(im);
    } else if (bt == TypeDesc::UINT16 || bt == TypeDesc::INT16) {
      Image<uint16_t> im(spec.width, spec.height, nch);
      read_into(*in, path, 0, 0, nch, im, 0, TypeDesc::UINT16);
      result.image = std::move(im);
    } else {
      Image<float> im(spec.width, spec.height, nch);
      read_into(*in, path, 0, 0, nch, im, 0, TypeDesc::FLOAT);
      check_finite(im, path);
      result.image = std::move(im);
    }
    result.channel_names = spec.channelnames;
    return result;
  }

  // Named channels: gather from whichever part holds each, as float.
  struct Where {
    int sub, ch;
  };
  std::vector<Where> where;
  std::vector<std::string> available;
  int width = -1, height = -1;
  for (const auto& want : options.channels) {
    bool found = false;
    for (int sub = 0; in->seek_subimage(sub, 0) && !found; ++sub) {
      const auto& spec = in->spec();
      for (int c = 0; c < spec.nchannels; ++c) {
        if (spec.channelnames[c] == want) {
          where.push_back({sub, c});
          if (width < 0) width = spec.width, height = spec.height;
          else if (spec.width != width || spec.height != height)
            throw Error(path, "channel '" + want + "' has a different size from the others");
          found = true;
          break;
        }
      }
    }
    if (!found) {
      available = list_channels(path);
      std::string list;
      for (const auto& a : available) list += (list.empty() ? "" : ", ") + a;
      throw Error(path, "no channel '" + want + "' (the file has: " + list + ")");
    }
  }
  Image<float> im(width, height, int(where.size()));
  for (std::size_t i = 0; i < where.size(); ++i) {
    in->seek_subimage(where[i].sub, 0);
    read_into(*in, path, where[i].sub, where[i].ch, where[i].ch + 1, im, int(i), TypeDesc::FLOAT);
  }
  check_finite(im, path);
  result.image = std::move(im);
  result.channel_names = options.channels;
  return result;
}

Image<float> read_image_float(const std::string& path, const ReadOptions& options) {
  return read_image(path, options).to_float();
}

// ---------------------------------------------------------------------------------------------
// Writing

namespace {
std::string lower_ext(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}
}  // namespace

bool is_writable_extension(const std::string& path) {
  const std::string e = lower_ext(path);
  return e == ".png" || e == ".exr" || e == ".tif" || e == ".tiff" || e == ".jpg" ||
         e == ".jpeg";
}

void check_writable(const std::string& path) {
  if (!is_writable_extension(path))
    throw Error(path, "unsupported output format (use .png, .exr, .tif or .jpg)");
  fs::path dir = fs::path(path).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw Error(path, "output folder does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw Error(path, "output folder is not writable");
  if (fs::is_directory(path, ec)) throw Error(path, "is a folder, not a file name");
}

void write_image(const std::string& path, ImageView<const float> image,
                 const WriteOptions& options) {
  check_writable(path);
  const std::string ext = lower_ext(path);
  TypeDesc type = TypeDesc::UINT16;
  switch (options.format) {
    case SampleFormat::kU8: type = TypeDesc::UINT8; break;
    case SampleFormat::kU16: type = TypeDesc::UINT16; break;
    case SampleFormat::kHalf: type = TypeDesc::HALF; break;
    case SampleFormat::kFloat: type = TypeDesc::FLOAT; break;
    case SampleFormat::kAuto:
      type = ext == ".exr" ? TypeDesc::HALF : (ext == ".jpg" || ext == ".jpeg") ? TypeDesc::UINT8
                                                                                : TypeDesc::UINT16;
  }
  if (ext == ".exr" && (type == TypeDesc::UINT8 || type == TypeDesc::UINT16)) type = TypeDesc::HALF;
  if ((ext == ".jpg" || ext == ".jpeg")) type = TypeDesc::UINT8;
  if (ext == ".png" && (type == TypeDesc::HALF || type == TypeDesc::FLOAT)) type = TypeDesc::UINT16;

  ImageSpec spec(image.width, image.height, image.channels, type);
  if (!options.channel_names.empty()) {
    CHECK_EQ(int(options.channel_names.size()), image.channels);
    spec.channelnames = options.channel_names;
  }
  if (image.channels == 4 || (image.channels == 2)) spec.alpha_channel = image.channels - 1;
  if (ext == ".exr") spec.attribute("compression", "zip");

  // Integer formats take values clamped to [0,1]; float formats take them as they are.
  const bool integer = type == TypeDesc::UINT8 || type == TypeDesc::UINT16;
  std::vector<float> buf(std::size_t(image.width) * image.height * image.channels);
  for (int y = 0; y < image.height; ++y) {
    const float* r = image.row(y);
    float* d = buf.data() + std::size_t(y) * image.width * image.channels;
    for (int i = 0; i < image.width * image.channels; ++i)
      d[i] = integer ? std::clamp(r[i], 0.0f, 1.0f) : r[i];
  }

  const fs::path target(path);
  const fs::path tmp = target.parent_path() /
                       fmt::format(".{}.tmp{}{}", target.stem().string(), ::getpid(), ext);
  {
    auto out = ImageOutput::create(tmp.string());
    if (!out) throw Error(path, "cannot create image writer (" + oiio_error("unknown format") + ")");
    if (!out->open(tmp.string(), spec)) {
      std::string e = oiio_error(out->geterror());
      throw Error(path, "cannot open for writing (" + e + ")");
    }
    const bool ok = out->write_image(TypeDesc::FLOAT, buf.data());
    const bool closed = out->close();
    if (!ok || !closed) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw Error(path, "write failed (" + oiio_error(out->geterror()) + ")");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(path, "cannot move the finished file into place");
  }
}

}  // namespace emaki::io
