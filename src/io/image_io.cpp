#include "io/image_io.h"

#include <dlfcn.h>
#include <fmt/format.h>
#include <link.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>

#include "core/error.h"
#include "core/limits.h"
#include "io/exr_header.h"
#include "io/exr_plain.h"
#include "io/oiio_backend.h"
#include "io/png_io.h"
#include "io/read_limits.h"
#include "io/temp_file.h"

namespace emaki::io {
namespace fs = std::filesystem;

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
  return image.index() == 0   ? PixelType::kU8
         : image.index() == 1 ? PixelType::kU16
                              : PixelType::kF32;
}

float AnyImage::value(int x, int y, int c) const {
  return std::visit([&](const auto& im) { return normalised(im(x, y, c)); }, image);
}

Image<float> AnyImage::to_float() && {
  if (auto* f = std::get_if<Image<float>>(&image)) return std::move(*f);
  return static_cast<const AnyImage&>(*this).to_float();
}

Image<float> AnyImage::to_float() const& {
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
// The OpenImageIO plugin

namespace detail {

// OpenImageIO's OpenEXR plugin resizes OpenEXR's global thread pool on every open, which races
// when two threads open files at once (ThreadSanitizer shows it); calls into the plugin are
// therefore taken one at a time. PNG, the common case, stays parallel.
std::mutex& oiio_mutex() {
  static std::mutex m;
  return m;
}

const OiioBackend& oiio_backend(const std::string& subject) {
  static const OiioBackend* backend = nullptr;
  static std::string failure;
  static std::once_flag once;
  std::call_once(once, [] {
    std::vector<std::string> candidates;
    if (const char* env = std::getenv("EMAKI_OIIO_MODULE")) candidates.push_back(env);
    // Relative to what holds this code (the installed layout, cmake/install.cmake): linked
    // into an executable, beside it or at PREFIX/lib/emaki from PREFIX/bin/emaki; in a shared
    // object (the Python module), beside it or at PREFIX/lib/emaki from
    // PREFIX/lib/python3/dist-packages, never relative to the python3 running it. Then where
    // the build put it.
    std::error_code ec;
    Dl_info self{};
    link_map* object = nullptr;
    const bool in_shared_object =
        dladdr1(reinterpret_cast<void*>(&oiio_backend), &self, reinterpret_cast<void**>(&object),
                RTLD_DL_LINKMAP) != 0 &&
        object && object->l_name && object->l_name[0] != '\0' && self.dli_fname;
    if (in_shared_object) {
      const fs::path here = fs::path(self.dli_fname).parent_path();
      candidates.push_back((here / "libemaki_io_oiio.so").string());
      candidates.push_back((here / "../../emaki/libemaki_io_oiio.so").string());
    } else if (const fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec) {
      candidates.push_back((exe.parent_path() / "libemaki_io_oiio.so").string());
      candidates.push_back((exe.parent_path() / "../lib/emaki/libemaki_io_oiio.so").string());
    }
#ifdef EMAKI_OIIO_MODULE_PATH
    candidates.push_back(EMAKI_OIIO_MODULE_PATH);
#endif
    // The first that exists is the plugin: if it cannot load (a library it needs is missing),
    // that is the error, naming the library, rather than a fall back to another build's plugin.
    for (const auto& c : candidates) {
      if (!fs::exists(c, ec)) continue;
      void* h = dlopen(c.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!h) {
        failure = dlerror();
        return;
      }
      using Fn = const OiioBackend* (*)();
      if (auto fn = reinterpret_cast<Fn>(dlsym(h, "emaki_oiio_backend"))) {
        using SetHook = void (*)(emaki::detail::ImageBlockHook);
        if (auto set = reinterpret_cast<SetHook>(dlsym(h, "emaki_oiio_set_image_hook")))
          set(emaki::detail::image_block_hook.load());
        backend = fn();
        return;
      }
      failure = c + ": not emaki's OpenImageIO plugin";
      return;
    }
    failure = "libemaki_io_oiio.so not found";
  });
  if (!backend) throw Error(subject, "cannot load the OpenImageIO plugin (" + failure + ")");
  return *backend;
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------
// Reading

namespace {

std::string lower_ext(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

void check_readable(const std::string& path) {
  // No file has a longer path (PATH_MAX), and a path read from a shot file can be any size:
  // name it capped rather than echo megabytes.
  if (path.size() > 4096) throw Error(echo(path, 200), "path is too long");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path, "file not found");
  if (fs::is_directory(path, ec)) throw Error(path, "is a folder, not an image file");
  // A FIFO or a device (/dev/zero, /dev/stdin) has no end or no size to check against, and a
  // reader would wait on it or read it forever.
  if (!fs::is_regular_file(path, ec)) throw Error(path, "is not a regular file");
}

bool has_png_signature(const unsigned char* bytes, std::size_t n) {
  static const unsigned char kSig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return n >= 8 && std::equal(bytes, bytes + 8, kSig);
}

bool is_png(const std::string& path) {
  unsigned char sig[8] = {};
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  const std::size_t n = std::fread(sig, 1, 8, f);
  std::fclose(f);
  return has_png_signature(sig, n);
}

// Picks channels by name from a PNG's R, G, B, A / Y, A (as float, like the EXR path).
AnyImage pick_png_channels(AnyImage png, const std::string& subject, const ReadOptions& options) {
  if (options.channels.empty()) return png;
  std::vector<int> idx;
  for (const auto& want : options.channels) {
    auto it = std::find(png.channel_names.begin(), png.channel_names.end(), want);
    if (it == png.channel_names.end()) {
      std::string list;
      for (const auto& n : png.channel_names) list += (list.empty() ? "" : ", ") + n;
      throw Error(subject, "no channel '" + echo(want) + "' (the file has: " + list + ")");
    }
    idx.push_back(int(it - png.channel_names.begin()));
  }
  detail::check_image_alloc<float>(subject, png.width(), png.height(), int64_t(idx.size()));
  Image<float> o =
      detail::allocate_image<float>(subject, png.width(), png.height(), int(idx.size()));
  for (int y = 0; y < o.height(); ++y)
    for (int x = 0; x < o.width(); ++x)
      for (std::size_t k = 0; k < idx.size(); ++k) o(x, y, int(k)) = png.value(x, y, idx[k]);
  AnyImage picked;
  picked.image = std::move(o);
  picked.channel_names = options.channels;
  return picked;
}

// OpenEXR allocates from header values while it opens a file, before OpenImageIO hands emaki a
// spec to check: the header is walked first (exr_header.h).
bool is_exr_file(const std::string& path) {
  unsigned char magic[4] = {};
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  const std::size_t n = std::fread(magic, 1, 4, f);
  std::fclose(f);
  return detail::has_exr_magic(magic, n);
}

void check_exr_file(const std::string& path) {
  if (lower_ext(path) != ".exr" && !is_exr_file(path)) return;
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw Error(path, "cannot open for reading");
  detail::check_exr_header(f.get(), path);
}

}  // namespace

std::vector<std::string> list_channels(const std::string& path) {
  check_readable(path);
  if (is_png(path)) return detail::read_png_header(path).channel_names;
  check_exr_file(path);
  std::vector<std::string> names;
  std::lock_guard lock(detail::oiio_mutex());
  if (std::string e = detail::oiio_backend(path).list_channels({path}, names); !e.empty())
    throw Error(path, e);
  return names;
}

namespace {

using File = std::unique_ptr<std::FILE, detail::FileCloser>;

File open_for_reading(const std::string& path) {
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) throw Error(path, "cannot open for reading");
  return f;
}

void rewind_or_throw(std::FILE* f, const std::string& path) {
  if (std::fseek(f, 0, SEEK_SET) != 0) throw Error(path, "cannot read the file");
}

// The image in the open file `f` (at its start): the format told by its first bytes, the
// header walked first for an EXR (`whole`: and its chunk tables to the end of the file).
AnyImage read_open_file(std::FILE* f, const std::string& path, const ReadOptions& options,
                        bool whole) {
  unsigned char magic[8] = {};
  const std::size_t n = std::fread(magic, 1, sizeof magic, f);
  rewind_or_throw(f, path);
  if (has_png_signature(magic, n) || lower_ext(path) == ".png")
    return pick_png_channels(detail::read_png(f, path), path, options);
  const bool exr = detail::has_exr_magic(magic, n);
  if (exr || lower_ext(path) == ".exr") {
    if (whole)
      detail::check_exr_complete(f, path);
    else
      detail::check_exr_header(f, path);
    // The files emaki writes are read without OpenImageIO (io/exr_plain.h).
    if (std::optional<AnyImage> plain = detail::read_plain_exr(f, path, options.channels))
      return std::move(*plain);
    rewind_or_throw(f, path);
  }
  AnyImage result;
  // OpenEXR reads through the open file; the other formats' readers open the path themselves.
  detail::OiioSource source{path};
  if (lower_ext(path) == ".exr") source.file = f;
  std::lock_guard lock(detail::oiio_mutex());
  if (std::string e = detail::oiio_backend(path).read(source, options, max_pixels(), result);
      !e.empty())
    throw Error(path, e);
  return result;
}

}  // namespace

// One open of the file for everything: telling its format, walking its header, decoding.
AnyImage read_image(const std::string& path, const ReadOptions& options) {
  check_readable(path);
  const File f = open_for_reading(path);
  return read_open_file(f.get(), path, options, false);
}

std::optional<AnyImage> read_image_if_complete(const std::string& path,
                                               const ReadOptions& options) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) == 0 || ec) return std::nullopt;
  const std::string ext = lower_ext(path);
  if (ext != ".exr") {
    if (!image_file_complete(path)) return std::nullopt;
    return read_image(path, options);
  }
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) return std::nullopt;
  try {
    detail::check_exr_complete(f.get(), path);
  } catch (const Error&) {
    return std::nullopt;
  }
  rewind_or_throw(f.get(), path);
  return read_open_file(f.get(), path, options, false);
}

std::vector<std::string> list_channels_memory(const void* data, std::size_t size,
                                              const std::string& name) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  if (has_png_signature(bytes, size) || lower_ext(name) == ".png")
    return detail::read_png_memory(data, size, name).channel_names;  // decoded: PNGs are small
  if (lower_ext(name) == ".exr" || detail::has_exr_magic(bytes, size))
    detail::check_exr_header(bytes, size, name);
  std::vector<std::string> names;
  std::lock_guard lock(detail::oiio_mutex());
  if (std::string e = detail::oiio_backend(name).list_channels({name, data, size}, names);
      !e.empty())
    throw Error(name, e);
  return names;
}

AnyImage read_image_memory(const void* data, std::size_t size, const std::string& name,
                           const ReadOptions& options) {
  if (has_png_signature(static_cast<const unsigned char*>(data), size) || lower_ext(name) == ".png")
    return pick_png_channels(detail::read_png_memory(data, size, name), name, options);
  if (lower_ext(name) == ".exr" ||
      detail::has_exr_magic(static_cast<const unsigned char*>(data), size))
    detail::check_exr_header(static_cast<const unsigned char*>(data), size, name);
  AnyImage result;
  std::lock_guard lock(detail::oiio_mutex());
  if (std::string e =
          detail::oiio_backend(name).read({name, data, size}, options, max_pixels(), result);
      !e.empty())
    throw Error(name, e);
  return result;
}

Image<float> read_image_float(const std::string& path, const ReadOptions& options) {
  return read_image(path, options).to_float();
}

// ---------------------------------------------------------------------------------------------
// Writing

bool is_writable_extension(const std::string& path) {
  const std::string e = lower_ext(path);
  return e == ".png" || e == ".exr" || e == ".tif" || e == ".tiff" || e == ".jpg" || e == ".jpeg";
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

namespace {

// A file's structure checked to its end without decoding its pixels (PNG, EXR); other formats
// are read back whole. Throws emaki::Error(subject).
void check_structure(const std::string& file, const std::string& ext, const std::string& subject) {
  if (ext == ".png") return detail::check_png_complete(file, 0, subject);
  if (ext == ".exr") {
    std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(file.c_str(), "rb"), &std::fclose);
    if (!f) throw Error(subject, "cannot open for reading");
    return detail::check_exr_complete(f.get(), subject);
  }
  AnyImage ignored;
  std::lock_guard lock(detail::oiio_mutex());
  if (std::string e = detail::oiio_backend(subject).read({file}, {}, max_pixels(), ignored);
      !e.empty())
    throw Error(subject, e);
}

}  // namespace

void write_image(const std::string& path, ImageView<const float> image,
                 const WriteOptions& options) {
  check_writable(path);
  const std::string ext = lower_ext(path);
  // 0 u8, 1 u16, 2 half, 3 float
  int type = 1;
  switch (options.format) {
    case SampleFormat::kU8:
      type = 0;
      break;
    case SampleFormat::kU16:
      type = 1;
      break;
    case SampleFormat::kHalf:
      type = 2;
      break;
    case SampleFormat::kFloat:
      type = 3;
      break;
    case SampleFormat::kAuto:
      type = ext == ".exr" ? 2 : (ext == ".jpg" || ext == ".jpeg") ? 0 : 1;
  }
  if (ext == ".exr" && type < 2) type = 2;
  if (ext == ".jpg" || ext == ".jpeg") type = 0;
  if (ext == ".png" && type > 1) type = 1;
  if (!options.channel_names.empty()) CHECK_EQ(int(options.channel_names.size()), image.channels);
  // Integer formats take values clamped to [0, 1]; float formats take them as they are.
  Image<float> clamped;
  if (type < 2 && ext != ".png") {
    clamped.reset(image.width, image.height, image.channels);
    for (int y = 0; y < image.height; ++y)
      for (int i = 0; i < image.width * image.channels; ++i)
        clamped.row(y)[i] = std::clamp(image.row(y)[i], 0.0f, 1.0f);
    image = clamped.cview();
  }

  // The temporary is created exclusively with an unpredictable name, so a file or symlink
  // planted beside the target is never written through.
  TempFile tmp(path, path);
  if (ext == ".png") {
    const int fd = tmp.release_fd();
    std::FILE* file = ::fdopen(fd, "wb");
    if (!file) {
      ::close(fd);
      throw Error(path, "cannot open for writing");
    }
    const uint64_t bytes = detail::write_png(file, image, type == 1, path);
    tmp.commit([&](const std::string& t) { detail::check_png_complete(t, bytes, path); });
    return;
  }
  if (ext == ".exr")
    if (const std::optional<std::string> bytes =
            detail::encode_plain_exr(image, options, type == 2)) {
      tmp.write(bytes->data(), bytes->size());
      tmp.commit([&](const std::string& t) { check_structure(t, ext, path); });
      return;
    }
  {
    std::lock_guard lock(detail::oiio_mutex());
    if (std::string e = detail::oiio_backend(path).write(tmp.path(), image, options, type);
        !e.empty())
      throw Error(path, e);
  }
  // OpenEXR reports success when its last writes (the chunk table) fail on a full disk: what it
  // wrote is read back before it may replace the target.
  tmp.commit([&](const std::string& t) { check_structure(t, ext, path); });
}

bool image_file_complete(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec) || fs::file_size(path, ec) == 0 || ec) return false;
  const std::string ext = lower_ext(path);
  if (ext != ".png" && ext != ".exr") return true;
  try {
    check_structure(path, ext, path);
    return true;
  } catch (const Error&) {
    return false;
  }
}

}  // namespace emaki::io
