#include "python/arrays.h"

#include <fmt/format.h>

#include <cstring>
#include <limits>

#include "core/limits.h"
#include "python/errors.h"
#include "shot/memory.h"

namespace emaki::python {
namespace {

// Channels per pixel an array may have: EXR files hold up to 64; the engine takes up to 4.
constexpr int64_t kMaxArrayChannels = 1024;

std::string dtype_name(const py::handle& obj, const std::string& format) {
  if (py::hasattr(obj, "dtype")) return py::str(obj.attr("dtype"));
  return "format '" + format + "'";
}

std::string shape_text(const py::buffer_info& info) {
  std::string s = "(";
  for (std::size_t i = 0; i < info.shape.size(); ++i)
    s += (i ? ", " : "") + std::to_string(info.shape[i]);
  return s + (info.shape.size() == 1 ? ",)" : ")");
}

SampleType type_of(const py::handle& obj, const py::buffer_info& info, const std::string& name) {
  std::string f = info.format;
  if (!f.empty() && (f[0] == '>' || f[0] == '!'))
    raise_input_error(name, fmt::format("dtype {} is big-endian; convert it with "
                                        "a.astype(a.dtype.newbyteorder('='))",
                                        dtype_name(obj, info.format)));
  if (!f.empty() && (f[0] == '@' || f[0] == '=' || f[0] == '<')) f = f.substr(1);
  if (f == "B" && info.itemsize == 1) return SampleType::kU8;
  if (f == "H" && info.itemsize == 2) return SampleType::kU16;
  if (f == "f" && info.itemsize == 4) return SampleType::kF32;
  raise_input_error(name, fmt::format("dtype {} is not supported: uint8, uint16 or float32",
                                      dtype_name(obj, info.format)));
}

// The array as an ImageView when its layout is one (packed pixels and channels, rows at a
// positive stride, aligned); false otherwise (a copy is needed).
template <typename T>
bool view(ArrayPlane& a) {
  const int w = a.width, h = a.height, c = a.depth;
  const py::buffer_info& info = a.info;
  const auto* base = static_cast<const unsigned char*>(info.ptr);
  const std::ptrdiff_t s = sizeof(T);
  const std::ptrdiff_t sy = info.strides[0], sx = info.strides[1];
  const std::ptrdiff_t sc = a.ndim == 3 ? info.strides[2] : s;
  const bool packed = (c == 1 || sc == s) && (w == 1 || sx == c * s);
  const std::ptrdiff_t row = h == 1 ? std::ptrdiff_t(w) * c * s : sy;
  const bool rows_ok = row % s == 0 && row >= std::ptrdiff_t(w) * c * s;
  if (!(packed && rows_ok && reinterpret_cast<std::uintptr_t>(base) % s == 0)) return false;
  a.plane = ImageView<const T>{reinterpret_cast<const T*>(base), w, h, c, row / s};
  return true;
}

template <typename T>
void copy(ArrayPlane& a) {
  const int w = a.width, h = a.height, c = a.depth;
  const py::buffer_info& info = a.info;
  const auto* base = static_cast<const unsigned char*>(info.ptr);
  const std::ptrdiff_t sy = info.strides[0], sx = info.strides[1];
  const std::ptrdiff_t sc = a.ndim == 3 ? info.strides[2] : std::ptrdiff_t(sizeof(T));
  Image<T> copy(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k)
        std::memcpy(&copy(x, y, k), base + y * sy + x * sx + k * sc, sizeof(T));
  a.plane = copy.cview();
  a.copy = std::move(copy);
  a.needs_copy = false;
}

std::size_t sample_bytes(SampleType t) {
  return t == SampleType::kU8 ? 1 : t == SampleType::kU16 ? 2 : 4;
}

}  // namespace

const void* ArrayPlane::data() const {
  return std::visit([](const auto& v) -> const void* { return v.data; }, plane);
}

ArrayPlane inspect_array(const py::handle& obj, const std::string& name) {
  if (!PyObject_CheckBuffer(obj.ptr()))
    raise_input_error(name, fmt::format("expects a numpy array (uint8, uint16 or float32), got {}",
                                        std::string(py::str(obj.get_type().attr("__name__")))));
  ArrayPlane a;
  a.name = name;
  a.info = py::reinterpret_borrow<py::buffer>(obj).request();
  const py::buffer_info& info = a.info;
  a.type = type_of(obj, info, name);
  if (info.ndim != 2 && info.ndim != 3)
    raise_input_error(name,
                      fmt::format("expects an HxW or HxWxC array, got shape {}", shape_text(info)));
  a.ndim = int(info.ndim);
  const int64_t h = info.shape[0], w = info.shape[1], c = a.ndim == 3 ? info.shape[2] : 1;
  if (h <= 0 || w <= 0 || c <= 0)
    raise_input_error(name, fmt::format("is empty (shape {})", shape_text(info)));
  if (c > kMaxArrayChannels)
    raise_input_error(name, fmt::format("has {} channels (shape {}); at most {}", c,
                                        shape_text(info), kMaxArrayChannels));
  translating(ErrorKind::kInput, {}, [&] { check_pixel_budget(name, w, h); });
  a.width = int(w), a.height = int(h), a.depth = int(c);
  switch (a.type) {
    case SampleType::kU8:
      a.needs_copy = !view<uint8_t>(a);
      break;
    case SampleType::kU16:
      a.needs_copy = !view<uint16_t>(a);
      break;
    case SampleType::kF32:
      a.needs_copy = !view<float>(a);
      break;
  }
  return a;
}

void check_copy_memory(const std::vector<const ArrayPlane*>& arrays) {
  int64_t bytes = 0;
  std::string first;
  for (const ArrayPlane* a : arrays) {
    if (!a->needs_copy) continue;
    const int64_t row = int64_t(a->width) * a->depth * int64_t(sample_bytes(a->type));
    bytes += (row + int64_t(kRowAlign) - 1) / int64_t(kRowAlign) * int64_t(kRowAlign) * a->height;
    if (first.empty()) first = a->name;
  }
  if (bytes == 0) return;
  translating(ErrorKind::kInput, {}, [&] {
    shot::check_memory(bytes, 0, first, "copying the arrays whose layout cannot be read in place");
  });
}

void copy_layout(ArrayPlane& a) {
  if (!a.needs_copy) return;
  switch (a.type) {
    case SampleType::kU8:
      return copy<uint8_t>(a);
    case SampleType::kU16:
      return copy<uint16_t>(a);
    case SampleType::kF32:
      return copy<float>(a);
  }
}

ArrayPlane array_plane(const py::handle& obj, const std::string& name) {
  ArrayPlane a = inspect_array(obj, name);
  check_copy_memory({&a});
  copy_layout(a);
  return a;
}

SampleType sample_type(const py::handle& dtype, const std::string& name, SampleType fallback) {
  if (dtype.is_none()) return fallback;
  py::dtype dt;
  try {
    dt = py::dtype::from_args(py::reinterpret_borrow<py::object>(dtype));
  } catch (const py::error_already_set&) {
    raise_input_error(name, fmt::format("'{}' is not a dtype: uint8, uint16 or float32",
                                        echo(std::string(py::str(dtype)))));
  }
  if (dt.kind() == 'u' && dt.itemsize() == 1) return SampleType::kU8;
  if (dt.kind() == 'u' && dt.itemsize() == 2) return SampleType::kU16;
  if (dt.kind() == 'f' && dt.itemsize() == 4) return SampleType::kF32;
  raise_input_error(name, fmt::format("dtype {} is not supported: uint8, uint16 or float32",
                                      std::string(py::str(py::handle(dt)))));
}

namespace {

template <typename T, typename Fn>
py::array fill_array(int w, int h, int c, bool squeeze, Fn&& value) {
  std::vector<py::ssize_t> shape{h, w};
  if (!(squeeze && c == 1)) shape.push_back(c);
  py::array_t<T> out(shape);
  T* dst = out.mutable_data();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int k = 0; k < c; ++k) *dst++ = value(x, y, k);
  return out;
}

}  // namespace

py::array to_array(const Image<float>& im, SampleType type, bool squeeze) {
  const int w = im.width(), h = im.height(), c = im.channels();
  switch (type) {
    case SampleType::kU8:
      return fill_array<uint8_t>(w, h, c, squeeze,
                                 [&](int x, int y, int k) { return to_u8(im(x, y, k)); });
    case SampleType::kU16:
      return fill_array<uint16_t>(w, h, c, squeeze,
                                  [&](int x, int y, int k) { return to_u16(im(x, y, k)); });
    case SampleType::kF32:
      break;
  }
  return fill_array<float>(w, h, c, squeeze, [&](int x, int y, int k) { return im(x, y, k); });
}

py::array to_array(const Image<int32_t>& im) {
  return fill_array<int32_t>(im.width(), im.height(), im.channels(), false,
                             [&](int x, int y, int k) { return im(x, y, k); });
}

Image<float> to_float_image(const ArrayPlane& a) {
  return std::visit(
      [](const auto& v) {
        Image<float> out(v.width, v.height, v.channels);
        for (int y = 0; y < v.height; ++y)
          for (int i = 0; i < v.width * v.channels; ++i) out.row(y)[i] = normalised(v.row(y)[i]);
        return out;
      },
      a.plane);
}

}  // namespace emaki::python
