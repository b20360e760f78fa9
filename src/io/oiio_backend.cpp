// OpenImageIO reading and writing, compiled into the plugin module only.
#include "io/oiio_backend.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <cmath>
#include <memory>

namespace emaki::io::detail {
namespace {
using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

std::string first_line(std::string e, const std::string& fallback) {
  if (e.empty()) e = fallback;
  if (auto nl = e.find('\n'); nl != std::string::npos) e.resize(nl);
  return e;
}

template <typename T>
bool read_into(ImageInput& in, int subimage, int chbegin, int chend, Image<T>& out, int dst_c,
               TypeDesc type) {
  const ImageSpec& spec = in.spec();
  const int nch = chend - chbegin;
  std::vector<T> buf(std::size_t(spec.width) * spec.height * nch);
  if (!in.read_image(subimage, 0, chbegin, chend, type, buf.data())) return false;
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x)
      for (int c = 0; c < nch; ++c)
        out(x, y, dst_c + c) = buf[(std::size_t(y) * spec.width + x) * nch + c];
  return true;
}

std::string check_finite(const Image<float>& im) {
  for (int y = 0; y < im.height(); ++y) {
    const float* r = im.row(y);
    for (int i = 0; i < im.width() * im.channels(); ++i)
      if (!std::isfinite(r[i]))
        return fmt::format("non-finite value (NaN or Inf) at pixel ({}, {}) channel {}",
                           i / im.channels(), y, i % im.channels());
  }
  return {};
}

std::string list_impl(const std::string& path, std::vector<std::string>& names) {
  auto in = ImageInput::open(path);
  if (!in) return "cannot read image (" + first_line(OIIO::geterror(), "unknown format") + ")";
  for (int sub = 0; in->seek_subimage(sub, 0); ++sub)
    for (const auto& n : in->spec().channelnames) names.push_back(n);
  return {};
}

std::string read_impl(const std::string& path, const ReadOptions& options, AnyImage& result) {
  auto in = ImageInput::open(path);
  if (!in) return "cannot read image (" + first_line(OIIO::geterror(), "unknown format") + ")";
  const std::string corrupt = "corrupt or truncated image";
  if (options.channels.empty()) {
    const ImageSpec spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0) return "image has no pixels";
    const int nch = spec.nchannels;
    const auto bt = TypeDesc::BASETYPE(spec.format.basetype);
    bool ok = true;
    if (bt == TypeDesc::UINT8 || bt == TypeDesc::INT8) {
      Image<uint8_t> im(spec.width, spec.height, nch);
      ok = read_into(*in, 0, 0, nch, im, 0, TypeDesc::UINT8);
      result.image = std::move(im);
    } else if (bt == TypeDesc::UINT16 || bt == TypeDesc::INT16) {
      Image<uint16_t> im(spec.width, spec.height, nch);
      ok = read_into(*in, 0, 0, nch, im, 0, TypeDesc::UINT16);
      result.image = std::move(im);
    } else {
      Image<float> im(spec.width, spec.height, nch);
      ok = read_into(*in, 0, 0, nch, im, 0, TypeDesc::FLOAT);
      if (ok)
        if (std::string e = check_finite(im); !e.empty()) return e;
      result.image = std::move(im);
    }
    if (!ok) return corrupt + " (" + first_line(in->geterror(), "read failed") + ")";
    result.channel_names = spec.channelnames;
    return {};
  }
  // Named channels: gather from whichever part holds each, as float.
  struct Where {
    int sub, ch;
  };
  std::vector<Where> where;
  int width = -1, height = -1;
  for (const auto& want : options.channels) {
    bool found = false;
    for (int sub = 0; in->seek_subimage(sub, 0) && !found; ++sub) {
      const auto& spec = in->spec();
      for (int c = 0; c < spec.nchannels; ++c) {
        if (spec.channelnames[c] != want) continue;
        where.push_back({sub, c});
        if (width < 0)
          width = spec.width, height = spec.height;
        else if (spec.width != width || spec.height != height)
          return "channel '" + want + "' has a different size from the others";
        found = true;
        break;
      }
    }
    if (!found) {
      std::vector<std::string> names;
      list_impl(path, names);
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      return "no channel '" + want + "' (the file has: " + list + ")";
    }
  }
  Image<float> im(width, height, int(where.size()));
  for (std::size_t i = 0; i < where.size(); ++i) {
    in->seek_subimage(where[i].sub, 0);
    if (!read_into(*in, where[i].sub, where[i].ch, where[i].ch + 1, im, int(i), TypeDesc::FLOAT))
      return corrupt + " (" + first_line(in->geterror(), "read failed") + ")";
  }
  if (std::string e = check_finite(im); !e.empty()) return e;
  result.image = std::move(im);
  result.channel_names = options.channels;
  return {};
}

std::string write_impl(const std::string& path, ImageView<const float> image,
                       const std::vector<std::string>& names, int type_code) {
  static const TypeDesc kTypes[4] = {TypeDesc::UINT8, TypeDesc::UINT16, TypeDesc::HALF,
                                     TypeDesc::FLOAT};
  ImageSpec spec(image.width, image.height, image.channels, kTypes[type_code]);
  if (!names.empty()) spec.channelnames = names;
  if (names.empty() && (image.channels == 4 || image.channels == 2))
    spec.alpha_channel = image.channels - 1;
  spec.attribute("compression", "zip");
  std::vector<float> buf(std::size_t(image.width) * image.height * image.channels);
  for (int y = 0; y < image.height; ++y) {
    const float* r = image.row(y);
    std::copy(r, r + std::size_t(image.width) * image.channels,
              buf.data() + std::size_t(y) * image.width * image.channels);
  }
  auto out = ImageOutput::create(path);
  if (!out)
    return "cannot create image writer (" + first_line(OIIO::geterror(), "unknown format") + ")";
  if (!out->open(path, spec))
    return "cannot open for writing (" + first_line(out->geterror(), "") + ")";
  const bool ok = out->write_image(TypeDesc::FLOAT, buf.data());
  const bool closed = out->close();
  if (!ok || !closed) return "write failed (" + first_line(out->geterror(), "") + ")";
  return {};
}

const OiioBackend kBackend{read_impl, list_impl, write_impl};

}  // namespace
}  // namespace emaki::io::detail

extern "C" const emaki::io::detail::OiioBackend* emaki_oiio_backend() {
  return &emaki::io::detail::kBackend;
}
