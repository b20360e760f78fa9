// OpenImageIO reading and writing, compiled into the plugin module only.
#include "io/oiio_backend.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/read_limits.h"

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

// The opened file. OpenImageIO keeps a pointer to the memory proxy, so the proxy lives beside
// the input and outlives it (members are destroyed in reverse order).
struct Opened {
  std::unique_ptr<OIIO::Filesystem::IOProxy> proxy;
  std::unique_ptr<ImageInput> in;
};

// The OpenImageIO reader for a file name: only the formats emaki documents. OpenImageIO on its
// own falls back to trying every reader it has (DICOM, camera raw, FFmpeg, ...) on a file that
// its extension's reader refuses, which puts every one of them in front of hostile bytes.
const char* format_for(const std::string& path) {
  std::string ext = path.substr(std::min(path.size(), path.rfind('.')));
  for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".exr") return "openexr";
  if (ext == ".tif" || ext == ".tiff") return "tiff";
  if (ext == ".jpg" || ext == ".jpeg") return "jpeg";
  return nullptr;
}

// OpenImageIO's memory reader as the readers see it (its type name and buffer stay), with reads
// confined to the buffer: the stock one copies from before the buffer when a reader asks at a
// negative offset, which a damaged EXR makes OpenEXR do (found by fuzz_exr; the reproducer is
// tests/data/hostile/exr/read_before_start.exr).
class ConfinedMemReader final : public OIIO::Filesystem::IOMemReader {
 public:
  using IOMemReader::IOMemReader;
  std::size_t read(void* buf, std::size_t size) override {
    const std::size_t n = pread(buf, size, m_pos);
    m_pos += int64_t(n);
    return n;
  }
  std::size_t pread(void* buf, std::size_t size, int64_t offset) override {
    const std::size_t total = m_buf.size();
    if (offset < 0 || uint64_t(offset) >= total || size == 0) return 0;
    size = std::min<std::size_t>(size, total - std::size_t(offset));
    std::memcpy(buf, m_buf.data() + offset, size);
    return size;
  }
};

std::string open_source(const OiioSource& source, Opened& o) {
  const char* format = format_for(source.path);
  if (!format) return "unsupported image format (emaki reads .png, .exr, .tif and .jpg files)";
  if (source.data)
    o.proxy = std::make_unique<ConfinedMemReader>(source.data, source.size);
  else if (source.file)
    o.proxy =
        std::make_unique<OIIO::Filesystem::IOFile>(source.file, OIIO::Filesystem::IOProxy::Read);
  o.in = ImageInput::create(format, false, nullptr, o.proxy.get());
  if (!o.in)
    return "cannot read image (" + first_line(OIIO::geterror(), "no reader for the format") + ")";
  ImageSpec spec;
  // The reader takes the proxy from the configuration (set on the input alone, OpenEXR's reader
  // opens the path again).
  ImageSpec config;
  if (o.proxy) {
    void* proxy = o.proxy.get();
    config.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy);
  }
  if (!o.in->open(source.path, spec, config))
    return "cannot read image (" + first_line(o.in->geterror(), "not a valid file") + ")";
  return {};
}

std::string window_text(int x, int y, int w, int h) {
  return fmt::format("origin ({}, {}) size {}x{}", x, y, w, h);
}

// Everything a part's header claims that sizes an allocation or a loop, checked before a pixel
// of it is read: issue 9's 1 MB EXR whose data window said 30000x30000 took 22 GB before it
// failed. Throws Error with an empty subject (the caller names the file).
void check_spec(const ImageSpec& spec) {
  if (spec.deep) throw Error("", "deep (multi-sample) images are not supported");
  if (spec.depth != 1 || spec.full_depth > 1 || spec.tile_depth > 1)
    throw Error("", "volume images are not supported");
  if (spec.nchannels < 1 || spec.nchannels > kMaxChannels)
    throw Error("", fmt::format("{} channels (emaki reads 1 to {})", spec.nchannels, kMaxChannels));
  if (int64_t(spec.channelnames.size()) != int64_t(spec.nchannels))
    throw Error("", "channel names do not match the channel count");
  // OpenImageIO keeps each window as an int origin and size; the end must be an int too.
  if (spec.width <= 0 || spec.height <= 0 || !checked_add(spec.x, spec.width) ||
      !checked_add(spec.y, spec.height))
    throw Error("", "data window (" + window_text(spec.x, spec.y, spec.width, spec.height) +
                        ") is empty or overflows");
  if (spec.full_width <= 0 || spec.full_height <= 0 || !checked_add(spec.full_x, spec.full_width) ||
      !checked_add(spec.full_y, spec.full_height))
    throw Error("", "display window (" +
                        window_text(spec.full_x, spec.full_y, spec.full_width, spec.full_height) +
                        ") is empty or overflows");
  check_pixel_budget("", spec.width, spec.height);
  if (spec.tile_width != 0 || spec.tile_height != 0) {
    if (spec.tile_width <= 0 || spec.tile_height <= 0)
      throw Error(
          "", fmt::format("tile size {}x{} is not positive", spec.tile_width, spec.tile_height));
    // The reader decodes whole tiles, so a row of tiles can hold more pixels than the image:
    // the padded size must fit the budget too.
    auto padded = [](int64_t size, int64_t tile) {
      return (size + tile - 1) / tile * tile;  // both positive ints: cannot overflow int64
    };
    const auto n = checked_mul<int64_t>(padded(spec.width, spec.tile_width),
                                        padded(spec.height, spec.tile_height));
    if (!n || *n > max_pixels())
      throw Error("", fmt::format("tiles of {}x{} make the {}x{} image exceed the pixel budget "
                                  "of {} pixels",
                                  spec.tile_width, spec.tile_height, spec.width, spec.height,
                                  max_pixels()));
  }
}

// Seeks to part `sub` (mip level 0); false past the last part, Error past kMaxParts.
bool seek_part(ImageInput& in, int sub) {
  if (sub >= kMaxParts) {
    if (in.seek_subimage(sub, 0))
      throw Error("", fmt::format("more than {} parts (subimages)", kMaxParts));
    return false;
  }
  return in.seek_subimage(sub, 0);
}

// Reads channels [chbegin, chend) of a part straight into channels dst_c... of `out`, through
// its padded rows: no second full-size buffer.
template <typename T>
bool read_into(ImageInput& in, int subimage, int chbegin, int chend, Image<T>& out, int dst_c,
               TypeDesc type) {
  return in.read_image(subimage, 0, chbegin, chend, type, &out(0, 0, dst_c),
                       OIIO::stride_t(out.channels() * sizeof(T)),
                       OIIO::stride_t(out.stride() * sizeof(T)));
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

std::string list_checked(const OiioSource& source, std::vector<std::string>& names) {
  Opened o;
  if (std::string e = open_source(source, o); !e.empty()) return e;
  for (int sub = 0; seek_part(*o.in, sub); ++sub) {
    const ImageSpec& spec = o.in->spec();
    if (spec.nchannels > kMaxChannels)
      throw Error("", fmt::format("{} channels in part {} (emaki reads 1 to {})", spec.nchannels,
                                  sub, kMaxChannels));
    for (const auto& n : spec.channelnames) names.push_back(n);
  }
  return {};
}

template <typename T>
std::string read_whole(ImageInput& in, const ImageSpec& spec, TypeDesc type, AnyImage& result) {
  check_image_alloc<T>("", spec.width, spec.height, spec.nchannels);
  Image<T> im = allocate_image<T>("", spec.width, spec.height, spec.nchannels);
  if (!read_into(in, 0, 0, spec.nchannels, im, 0, type))
    return "corrupt or truncated image (" + first_line(in.geterror(), "read failed") + ")";
  if constexpr (std::is_same_v<T, float>)
    if (std::string e = check_finite(im); !e.empty()) return e;
  result.image = std::move(im);
  result.channel_names = spec.channelnames;
  return {};
}

// Reads the channels `picks` (file channel -> channel of `out`) of part `sub` (the current one)
// from one pass over its pixels. Scanline files are read a band of rows at a time, the span of
// the picked channels into a small buffer, so memory stays the output's; a tiled part reads one
// channel at a time (studio renders are scanline files).
std::string read_part_channels(ImageInput& in, int sub,
                               const std::vector<std::pair<int, int>>& picks, Image<float>& out) {
  const ImageSpec& spec = in.spec();
  const auto failed = [&in] {
    return "corrupt or truncated image (" + first_line(in.geterror(), "read failed") + ")";
  };
  if (spec.tile_width != 0) {
    for (const auto& [ch, dst] : picks)
      if (!read_into(in, sub, ch, ch + 1, out, dst, TypeDesc::FLOAT)) return failed();
    return {};
  }
  int first = spec.nchannels, last = -1;
  for (const auto& [ch, dst] : picks) first = std::min(first, ch), last = std::max(last, ch);
  const int span = last - first + 1;
  // 64 rows: a whole number of OpenEXR's blocks (1, 16 or 32 rows) in every compression.
  constexpr int kBand = 64;
  const int w = spec.width;
  std::vector<float> band(std::size_t(w) * std::size_t(std::min(kBand, spec.height)) *
                          std::size_t(span));
  for (int y0 = 0; y0 < spec.height; y0 += kBand) {
    const int y1 = std::min(spec.height, y0 + kBand);
    if (!in.read_scanlines(sub, 0, spec.y + y0, spec.y + y1, 0, first, last + 1, TypeDesc::FLOAT,
                           band.data()))
      return failed();
    for (int y = y0; y < y1; ++y) {
      const float* row = band.data() + std::size_t(y - y0) * std::size_t(w) * std::size_t(span);
      float* o = out.row(y);
      for (const auto& [ch, dst] : picks)
        for (int x = 0; x < w; ++x)
          o[std::ptrdiff_t(x) * out.channels() + dst] = row[std::ptrdiff_t(x) * span + ch - first];
    }
  }
  return {};
}

std::string read_checked(const OiioSource& source, const ReadOptions& options, AnyImage& result) {
  Opened o;
  if (std::string e = open_source(source, o); !e.empty()) return e;
  ImageInput& in = *o.in;
  if (options.channels.empty()) {
    const ImageSpec spec = in.spec();
    check_spec(spec);
    const auto bt = TypeDesc::BASETYPE(spec.format.basetype);
    if (bt == TypeDesc::UINT8 || bt == TypeDesc::INT8)
      return read_whole<uint8_t>(in, spec, TypeDesc::UINT8, result);
    if (bt == TypeDesc::UINT16 || bt == TypeDesc::INT16)
      return read_whole<uint16_t>(in, spec, TypeDesc::UINT16, result);
    return read_whole<float>(in, spec, TypeDesc::FLOAT, result);
  }
  // Named channels: gather from whichever part holds each, as float.
  struct Where {
    int sub, ch;
  };
  std::vector<Where> where;
  int width = -1, height = -1;
  for (const auto& want : options.channels) {
    bool found = false;
    for (int sub = 0; !found && seek_part(in, sub); ++sub) {
      const auto& spec = in.spec();
      for (int c = 0; c < spec.nchannels && c < int(spec.channelnames.size()); ++c) {
        if (spec.channelnames[c] != want) continue;
        check_spec(spec);
        where.push_back({sub, c});
        if (width < 0)
          width = spec.width, height = spec.height;
        else if (spec.width != width || spec.height != height)
          return "channel '" + echo(want) + "' has a different size from the others";
        found = true;
        break;
      }
    }
    if (!found) {
      std::vector<std::string> names;
      try {
        list_checked(source, names);
      } catch (const Error&) {
      }
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      return "no channel '" + echo(want) + "' (the file has: " + echo(list, 400) + ")";
    }
  }
  check_image_alloc<float>("", width, height, int64_t(where.size()));
  Image<float> im = allocate_image<float>("", width, height, int(where.size()));
  // Each part is decoded once: a compressed file is decompressed whole however few of its
  // channels are asked for, so one channel at a time would decode it once per channel (24 times
  // for a frame of passes).
  std::vector<int> parts;
  for (const Where& w : where)
    if (std::find(parts.begin(), parts.end(), w.sub) == parts.end()) parts.push_back(w.sub);
  for (const int sub : parts) {
    if (!in.seek_subimage(sub, 0))
      return "corrupt or truncated image (" + first_line(in.geterror(), "read failed") + ")";
    std::vector<std::pair<int, int>> picks;  // the part's channel -> the image's
    for (std::size_t i = 0; i < where.size(); ++i)
      if (where[i].sub == sub) picks.emplace_back(where[i].ch, int(i));
    if (std::string e = read_part_channels(in, sub, picks, im); !e.empty()) return e;
  }
  if (std::string e = check_finite(im); !e.empty()) return e;
  result.image = std::move(im);
  result.channel_names = options.channels;
  return {};
}

// The module's entry points turn every exception into a message: nothing is thrown across the
// dlopen boundary, and OpenImageIO or OpenEXR running out of memory is an error, not an abort.
template <typename F>
std::string guarded(F&& f) {
  try {
    return f();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::bad_alloc&) {
    return "not enough memory to read the image";
  } catch (const std::exception& e) {
    return first_line(e.what(), "read failed");
  }
}

std::string read_impl(const OiioSource& source, const ReadOptions& options, int64_t max_pixels,
                      AnyImage& result) {
  // This module may hold its own copy of the budget (see OiioBackend): make it the caller's, for
  // this call only (a shot's budget must not outlive its work).
  const ScopedMaxPixels budget(max_pixels);
  return guarded([&] { return read_checked(source, options, result); });
}

std::string list_impl(const OiioSource& source, std::vector<std::string>& names) {
  return guarded([&] { return list_checked(source, names); });
}

std::string write_impl(const std::string& path, ImageView<const float> image,
                       const WriteOptions& options, int type_code) {
  const std::vector<std::string>& names = options.channel_names;
  static const TypeDesc kTypes[4] = {TypeDesc::UINT8, TypeDesc::UINT16, TypeDesc::HALF,
                                     TypeDesc::FLOAT};
  ImageSpec spec(image.width, image.height, image.channels, kTypes[type_code]);
  if (!names.empty()) spec.channelnames = names;
  if (names.empty() && (image.channels == 4 || image.channels == 2))
    spec.alpha_channel = image.channels - 1;
  spec.attribute("compression", options.compression);
  for (const auto& [name, value] : options.attributes) spec.attribute(name, value);
  if (options.chromaticities.size() == 8)
    spec.attribute("chromaticities", TypeDesc(TypeDesc::FLOAT, 8), options.chromaticities.data());
  // OpenImageIO stamps EXRs with the time of writing (capDate) unless told a date: a fixed one
  // makes the same image the same file, so runs (and farm tasks) can be compared byte for byte.
  spec.attribute("DateTime", "2000:01:01 00:00:00");
  auto out = ImageOutput::create(path);
  if (!out)
    return "cannot create image writer (" + first_line(OIIO::geterror(), "unknown format") + ")";
  if (!out->open(path, spec))
    return "cannot open for writing (" + first_line(out->geterror(), "") + ")";
  // Straight from the view, rows `stride` floats apart: no copy of the image (the layered EXR's
  // is 68 MB at 960x540).
  const bool ok = out->write_image(TypeDesc::FLOAT, image.data, OIIO::AutoStride,
                                   image.stride * OIIO::stride_t(sizeof(float)));
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

// The loading program's image hook (core/image.h), handed over on loading: this module holds
// its own copy of the inline variable, and images read here follow the front end's settings.
extern "C" void emaki_oiio_set_image_hook(emaki::detail::ImageBlockHook hook) {
  emaki::detail::image_block_hook.store(hook);
}
