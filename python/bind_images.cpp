// emaki.read_image / write_image / image_channels: io/image_io.h over numpy arrays;
// emaki.convert_colorspace: colour/colour.h over one.
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "colour/colour.h"
#include "core/limits.h"
#include "io/image_io.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "python/errors.h"

namespace emaki::python {
namespace {

constexpr const char* kReadDoc =
    R"(read_image(path, channels=None)
--

Reads an image file: PNG (8/16-bit), EXR (half/float), TIFF, JPEG.

Args:
    path: the file (str or os.PathLike).
    channels: channel names to read, in order (e.g. ['normal.X', 'normal.Y', 'normal.Z']),
        searched in every part of a multilayer EXR; None (default): every channel.

Returns:
    An array in the file's precision: uint8, uint16 or float32 (half is read as float);
    HxW for one channel (a gray file, or one channel asked for), else HxWxC. The same
    convention as render(), template() and synthesize(), and write_image() takes it back.

Raises:
    emaki.FileError: (also an OSError) a missing, unreadable or corrupt file, one over the
        pixel budget, or a channel it does not have (the message lists those it has).
)";

constexpr const char* kWriteDoc = R"(write_image(path, image, *, channels=None, depth=None)
--

Writes an image file atomically (a temporary, then a rename).

The format follows the extension: .png, .exr, .tif/.tiff, .jpg/.jpeg.

Args:
    path: the file (str or os.PathLike); its folder must exist.
    image: HxW or HxWxC array, uint8, uint16 or float32 (integers mean [0, 1]).
    channels: EXR channel names, one per channel (e.g. ['diffuse.Y']); None (default):
        R, G, B, A (or Y for one channel).
    depth: sample format: '8', '16', 'half' or 'float' (8 or 16 as int too); None (default):
        that of the array (float32: float; PNG takes 8 or 16 bits, JPEG 8, EXR half or float).
        Integer formats clamp to [0, 1] and round.

Raises:
    emaki.InputError: a bad array, channel list or depth.
    emaki.FileError: the file cannot be written.
)";

constexpr const char* kConvertDoc =
    R"(convert_colorspace(image, src, dst, config=None)
--

Converts an image's colours from one OpenColorIO colour space to another, as a shot's inputs
are converted (docs/shot_file.md, Colour management).

Args:
    image: HxWxC array with C >= 3, uint8, uint16 or float32 (integers mean [0, 1]); the first
        three channels are converted, the others (alpha) kept.
    src: the image's colour space (a name or a role of the config, e.g. 'sRGB texture',
        'ACEScg', 'scene_linear').
    dst: the colour space wanted.
    config: an OpenColorIO config file (str or os.PathLike); None (default): $OCIO when set,
        else emaki's built-in config.

Returns:
    A new HxWxC float32 array.

Raises:
    emaki.InputError: a bad array, an unknown colour space (naming src or dst and the nearest
        names), or a config that cannot be used.
)";

py::array convert_colorspace(const py::handle& image, const std::string& src,
                             const std::string& dst,
                             const std::optional<std::filesystem::path>& config) {
  const ArrayPlane a = array_plane(image, "image");
  if (a.channels() < 3)
    raise_input_error("image", fmt::format("has {} channels; needs at least 3", a.channels()));
  Image<float> pixels = translating(ErrorKind::kInput, {}, [&] {
    const std::shared_ptr<const colour::Config> c =
        colour::Config::open(config ? config->string() : "", "config");
    c->require_space("src", src);
    c->require_space("dst", dst);
    Image<float> out = to_float_image(a);
    c->convert(out.view(), src, dst);
    return out;
  });
  return to_array(pixels, SampleType::kF32, false);
}

py::array read_image(const std::filesystem::path& path,
                     const std::optional<std::vector<std::string>>& channels) {
  io::ReadOptions options;
  if (channels) options.channels = *channels;
  const io::AnyImage im =
      without_gil(ErrorKind::kFile, {}, [&] { return io::read_image(path.string(), options); });
  return std::visit(
      [](const auto& image) -> py::array {
        using T = std::remove_const_t<std::remove_reference_t<decltype(image(0, 0))>>;
        // One channel is HxW, as render() and synthesize() return it (docs/python.md).
        py::array_t<T> out =
            image.channels() == 1
                ? py::array_t<T>({image.height(), image.width()})
                : py::array_t<T>({image.height(), image.width(), image.channels()});
        T* dst = out.mutable_data();
        const std::size_t row = std::size_t(image.width()) * image.channels();
        for (int y = 0; y < image.height(); ++y, dst += row)
          std::copy(image.row(y), image.row(y) + row, dst);
        return out;
      },
      im.image);
}

io::SampleFormat write_format(const py::handle& depth, SampleType type) {
  if (depth.is_none())
    return type == SampleType::kU8    ? io::SampleFormat::kU8
           : type == SampleType::kU16 ? io::SampleFormat::kU16
                                      : io::SampleFormat::kFloat;
  const std::string d = py::str(depth);
  if (d == "8") return io::SampleFormat::kU8;
  if (d == "16") return io::SampleFormat::kU16;
  if (d == "half") return io::SampleFormat::kHalf;
  if (d == "float") return io::SampleFormat::kFloat;
  raise_input_error("depth",
                    fmt::format("must be '8', '16', 'half' or 'float', got '{}'", echo(d)));
}

void write_image(const std::filesystem::path& path, const py::handle& image,
                 const std::optional<std::vector<std::string>>& channels, const py::handle& depth) {
  const ArrayPlane a = array_plane(image, "image");
  io::WriteOptions options;
  options.format = write_format(depth, a.type);
  if (channels) {
    if (int(channels->size()) != a.channels())
      raise_input_error("channels", fmt::format("names {} channels but the image has {}",
                                                channels->size(), a.channels()));
    options.channel_names = *channels;
  }
  without_gil(ErrorKind::kFile, {}, [&] {
    const Image<float> pixels = to_float_image(a);
    io::write_image(path.string(), pixels.cview(), options);
  });
}

std::vector<std::string> image_channels(const std::filesystem::path& path) {
  return without_gil(ErrorKind::kFile, {}, [&] { return io::list_channels(path.string()); });
}

}  // namespace

void bind_images(py::module_& m) {
  m.def("read_image", &read_image, kReadDoc, py::arg("path"), py::arg("channels") = py::none());
  m.def("write_image", &write_image, kWriteDoc, py::arg("path"), py::arg("image"), py::kw_only(),
        py::arg("channels") = py::none(), py::arg("depth") = py::none());
  m.def("convert_colorspace", &convert_colorspace, kConvertDoc, py::arg("image"), py::arg("src"),
        py::arg("dst"), py::arg("config") = py::none());
  m.def("image_channels", &image_channels,
        "image_channels(path)\n--\n\nA list[str]: the channel names of every part of an image "
        "file, in "
        "order (e.g. 'normal.X', ...). "
        "Raises emaki.FileError for a file that cannot be read.",
        py::arg("path"));
}

}  // namespace emaki::python
