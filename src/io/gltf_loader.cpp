#include "io/gltf_loader.h"

#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/limits.h"

namespace emaki::io {

// ---------------------------------------------------------------------------------------------
// JSON pre-scan

JsonShape scan_json_shape(std::string_view json) {
  JsonShape shape;
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character cannot end the string
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      ++shape.containers;
      shape.max_depth = std::max(shape.max_depth, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return shape;
}

namespace {

namespace fs = std::filesystem;
using scene::Scene;

// tinygltf's messages can span lines and quote whole data: uris; the CLI prints one short line.
std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return echo(s, 240);
}

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A double from the JSON that must become a finite float.
bool finite_float(double v) {
  return std::isfinite(v) && std::abs(v) <= double(FLT_MAX);
}

// ---------------------------------------------------------------------------------------------
// External files: tinygltf reads buffers and images through these callbacks, which refuse
// paths outside the scene's folder (unless allowed), non-regular files and oversized files.

struct FileAccess {
  fs::path root;  // canonical folder of the scene; empty: no external file may be read
  bool allow_outside = false;
  std::string refused;  // the first refusal, a sentence for the error line
  int64_t bytes_read = 0;

  void refuse(const std::string& why) {
    if (refused.empty()) refused = why;
  }
};

bool inside(const fs::path& path, const fs::path& root) {
  const fs::path rel = path.lexically_relative(root);
  return !rel.empty() && !rel.is_absolute() && *rel.begin() != "..";
}

bool file_exists(const std::string& path, void* user) {
  auto* files = static_cast<FileAccess*>(user);
  if (files->root.empty()) {
    files->refuse(
        fmt::format("uri '{}' names an external file, which a scene loaded from memory "
                    "cannot read",
                    echo(path)));
    return false;
  }
  std::error_code ec;
  return fs::exists(path, ec);
}

// glTF uris are not shell words: no ~ or $VAR expansion.
std::string expand_path(const std::string& path, void*) {
  return path;
}

bool read_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
               void* user) {
  auto* files = static_cast<FileAccess*>(user);
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec || files->root.empty()) {
    files->refuse(fmt::format("uri '{}' cannot be resolved", echo(path)));
    *err = "refused";
    return false;
  }
  if (!files->allow_outside && !inside(real, files->root)) {
    files->refuse(
        fmt::format("uri '{}' leads outside the scene's folder (to '{}'); "
                    "--allow-outside-paths reads it anyway",
                    echo(path), echo(real.string())));
    *err = "refused";
    return false;
  }
  if (!fs::is_regular_file(real, ec)) {
    files->refuse(fmt::format("uri '{}' is not a regular file", echo(path)));
    *err = "refused";
    return false;
  }
  const std::uintmax_t size = fs::file_size(real, ec);
  const auto total = checked_add<int64_t>(
      files->bytes_read, int64_t(std::min<std::uintmax_t>(size, uint64_t(kMaxFileBytes) + 1)));
  if (ec || size > uint64_t(kMaxFileBytes) || !total || *total > kMaxFileBytes) {
    files->refuse(fmt::format("uri '{}' is {} bytes; external files may hold {} bytes in all",
                              echo(path), size, kMaxFileBytes));
    *err = "refused";
    return false;
  }
  std::ifstream in(real, std::ios::binary);
  out->resize(size);
  if (size > 0 && !in.read(reinterpret_cast<char*>(out->data()), std::streamsize(size))) {
    *err = "cannot be read";
    return false;
  }
  files->bytes_read = *total;
  return true;
}

bool write_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "the loader writes nothing";
  return false;
}

// ---------------------------------------------------------------------------------------------
// Images: tinygltf hands every image's bytes to this callback while it parses. Nothing is
// decoded here: the header's size is checked against the pixel budget and the encoded bytes are
// kept, so that only base-colour textures are decoded, later, within kMaxTexturePixels.

struct ImageAccess {
  const tinygltf::Model* model = nullptr;
  std::string error;  // the first problem, a sentence for the error line

  bool fail(const std::string& why) {
    if (error.empty()) error = why;
    return false;
  }
};

uint32_t be32(const unsigned char* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}
uint32_t be16(const unsigned char* p) {
  return uint32_t(p[0]) << 8 | uint32_t(p[1]);
}

// Width and height from a PNG's IHDR or a JPEG's frame header; false if it is neither.
bool image_header_size(const unsigned char* p, std::size_t n, int64_t& w, int64_t& h) {
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a};
  if (n >= 24 && std::memcmp(p, kPng, 8) == 0 && std::memcmp(p + 12, "IHDR", 4) == 0) {
    w = be32(p + 16);
    h = be32(p + 20);
    return true;
  }
  if (n < 4 || p[0] != 0xff || p[1] != 0xd8) return false;
  std::size_t i = 2;
  while (i + 4 <= n) {
    if (p[i] != 0xff) return false;
    const unsigned m = p[i + 1];
    if (m == 0xff) {  // fill byte
      ++i;
      continue;
    }
    if (m == 0x01 || (m >= 0xd0 && m <= 0xd8)) {  // markers without a length
      i += 2;
      continue;
    }
    const std::size_t len = be16(p + i + 2);
    if (len < 2) return false;
    const bool frame = m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc;
    if (frame) {
      if (i + 9 > n) return false;
      h = be16(p + i + 5);
      w = be16(p + i + 7);
      return true;
    }
    i += 2 + len;
  }
  return false;
}

bool keep_encoded_image(tinygltf::Image* image, const int index, std::string*, std::string*, int,
                        int, const unsigned char* bytes, int size, void* user) {
  auto* access = static_cast<ImageAccess*>(user);
  std::size_t n = size > 0 ? std::size_t(size) : 0;
  if (image->bufferView >= 0) {
    // tinygltf computes the pointer without checking the view lies inside its buffer.
    const tinygltf::Model& m = *access->model;
    if (std::size_t(image->bufferView) >= m.bufferViews.size())
      return access->fail(fmt::format("image {} refers to buffer view {}, but the file has {}",
                                      index, image->bufferView, m.bufferViews.size()));
    const tinygltf::BufferView& view = m.bufferViews[image->bufferView];
    if (view.buffer < 0 || std::size_t(view.buffer) >= m.buffers.size())
      return access->fail(fmt::format("buffer view {} refers to buffer {}, but the file has {}",
                                      image->bufferView, view.buffer, m.buffers.size()));
    const auto end = checked_add<uint64_t>(view.byteOffset, view.byteLength);
    if (!end || *end > m.buffers[view.buffer].data.size() || view.byteLength > uint64_t(INT32_MAX))
      return access->fail(fmt::format(
          "image {}: buffer view {} (offset {}, length {}) is out of range of buffer {} ({} bytes)",
          index, image->bufferView, view.byteOffset, view.byteLength, view.buffer,
          m.buffers[view.buffer].data.size()));
    n = view.byteLength;
  }
  const std::string name = image->uri.empty()
                               ? fmt::format("image {}", index)
                               : fmt::format("image {} ('{}')", index, echo(image->uri));
  int64_t w = 0, h = 0;
  if (n == 0 || !image_header_size(bytes, n, w, h))
    return access->fail(name + " is neither a PNG nor a JPEG file");
  if (w <= 0 || h <= 0) return access->fail(fmt::format("{} has size {}x{}", name, w, h));
  const auto pixels = checked_mul<int64_t>(w, h);
  if (!pixels || *pixels > max_pixels())
    return access->fail(
        fmt::format("{} is {}x{} pixels, over the pixel budget of {} (raise it with --max-pixels)",
                    name, w, h, max_pixels()));
  image->image.assign(bytes, bytes + n);
  image->width = int(w);
  image->height = int(h);
  image->component = 0;  // not decoded yet
  image->bits = 0;
  return true;
}

// ---------------------------------------------------------------------------------------------
// GLB container: checked here, before tinygltf, which reads 8 bytes past a BIN chunk whose
// length reaches the end of the file.

std::string_view glb_json_chunk(std::string_view bytes, const std::string& name,
                                std::size_t& length) {
  auto u32 = [&](std::size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20) throw Error(name, "not a valid glTF file: truncated GLB header");
  if (u32(4) != 2)
    throw Error(name, fmt::format("not a valid glTF file: GLB version {}, expected 2", u32(4)));
  const uint64_t total = u32(8);
  if (total > bytes.size() || total < 20)
    throw Error(name, fmt::format("not a valid glTF file: the GLB header says {} bytes, the file "
                                  "has {}",
                                  total, bytes.size()));
  const uint64_t json_length = u32(12);
  const uint64_t json_end = 20 + json_length;
  if (u32(16) != 0x4E4F534A || json_length == 0 || json_end > total)
    throw Error(name, "not a valid glTF file: the GLB has no valid JSON chunk");
  if (json_end < total) {
    const uint64_t bin_length = json_end + 8 <= total ? u32(json_end) : 0;
    if (json_end + 8 > total || json_end + 8 + bin_length > total)
      throw Error(name, "not a valid glTF file: the GLB's second chunk runs past its end");
  }
  length = std::size_t(total);
  return bytes.substr(20, json_length);
}

void check_json_shape(std::string_view json, const std::string& name) {
  const JsonShape shape = scan_json_shape(json);
  if (shape.max_depth > kMaxJsonDepth)
    throw Error(name, fmt::format("not a valid glTF file: its JSON nests {} levels deep (at most "
                                  "{} allowed)",
                                  shape.max_depth, kMaxJsonDepth));
  if (shape.containers > kMaxJsonContainers)
    throw Error(name, fmt::format("not a valid glTF file: its JSON holds {} arrays and objects "
                                  "(at most {} allowed)",
                                  shape.containers, kMaxJsonContainers));
}

// ---------------------------------------------------------------------------------------------
// tinygltf::Model -> Scene

class Loader {
 public:
  Loader(const std::string& path, const tinygltf::Model& model) : path_(path), m_(model) {}

  [[noreturn]] void fail(const std::string& message) const { throw Error(path_, message); }

  Scene load() {
    Scene s;
    s.source = path_;
    load_textures_and_materials(s);
    load_meshes(s);
    load_skins(s);
    load_cameras(s);
    load_nodes(s);
    load_animations(s);
    check_drawn_size(s);
    check_drawable(s);
    return s;
  }

 private:
  struct Span {
    const unsigned char* data = nullptr;
    std::size_t stride = 0;
  };

  // ---- Accessors ----

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || std::size_t(index) >= m_.accessors.size())
      fail(fmt::format("{} refers to accessor {}, but the file has {}", what, index,
                       m_.accessors.size()));
    const tinygltf::Accessor& acc = m_.accessors[index];
    if (acc.sparse.isSparse)
      fail(fmt::format("{} (accessor {}) is sparse, which is not supported", what, index));
    return acc;
  }

  int components(const tinygltf::Accessor& acc, int index, const std::string& what) const {
    const int comps = tinygltf::GetNumComponentsInType(acc.type);
    const int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    if (comps <= 0 || comps > 16 || csize <= 0 || csize > 8)
      fail(fmt::format("{} (accessor {}) has an invalid type", what, index));
    return comps;
  }

  // The number of values an accessor yields, charged to the file's kMaxAccessorValues.
  std::size_t values_of(const tinygltf::Accessor& acc, int comps, int index,
                        const std::string& what) {
    const auto n = checked_mul<uint64_t>(acc.count, uint64_t(comps));
    const auto total = n ? checked_add<uint64_t>(values_read_, *n) : std::nullopt;
    if (!total || *total > uint64_t(kMaxAccessorValues))
      fail(
          fmt::format("{} (accessor {}) has count {}: the file's accessors would hold more than "
                      "{} values",
                      what, index, acc.count, kMaxAccessorValues));
    values_read_ = *total;
    return std::size_t(*n);
  }

  // Where an accessor's elements lie, checking with overflow-checked arithmetic that every byte
  // it touches is inside its buffer view and the view inside its buffer.
  Span locate(const tinygltf::Accessor& acc, int comps, int index, const std::string& what) const {
    if (acc.bufferView < 0) {
      if (acc.count > uint64_t(kMaxZeroAccessorElements))
        fail(
            fmt::format("{} (accessor {}) has no buffer view: its {} elements would all be zero "
                        "(at most {} allowed)",
                        what, index, acc.count, kMaxZeroAccessorElements));
      return {};
    }
    if (std::size_t(acc.bufferView) >= m_.bufferViews.size())
      fail(fmt::format("{} (accessor {}) refers to buffer view {}, but the file has {}", what,
                       index, acc.bufferView, m_.bufferViews.size()));
    const tinygltf::BufferView& view = m_.bufferViews[acc.bufferView];
    if (view.buffer < 0 || std::size_t(view.buffer) >= m_.buffers.size())
      fail(fmt::format("buffer view {} refers to buffer {}, but the file has {}", acc.bufferView,
                       view.buffer, m_.buffers.size()));
    const tinygltf::Buffer& buffer = m_.buffers[view.buffer];
    const uint64_t elem =
        uint64_t(comps) * uint64_t(tinygltf::GetComponentSizeInBytes(acc.componentType));
    if (view.byteStride != 0 && (view.byteStride < elem || view.byteStride > 252))
      fail(fmt::format("buffer view {} has byteStride {}, but {} (accessor {}) needs {} to 252",
                       acc.bufferView, view.byteStride, what, index, elem));
    const uint64_t stride = view.byteStride > 0 ? view.byteStride : elem;
    const auto view_end = checked_add<uint64_t>(view.byteOffset, view.byteLength);
    if (!view_end || *view_end > buffer.data.size())
      fail(fmt::format(
          "buffer view {} (offset {}, length {}) is out of range of buffer {}, "
          "which has {} bytes",
          acc.bufferView, view.byteOffset, view.byteLength, view.buffer, buffer.data.size()));
    // Even an empty accessor's offset must lie in its view: the data pointer is formed from it.
    std::optional<uint64_t> need = uint64_t(acc.byteOffset);
    if (acc.count > 0) {
      const auto span = checked_mul<uint64_t>(stride, acc.count - 1);
      need = span ? checked_add<uint64_t>(*span, elem) : std::nullopt;
      need = need ? checked_add<uint64_t>(*need, acc.byteOffset) : std::nullopt;
    }
    if (!need || *need > view.byteLength)
      fail(fmt::format(
          "{} (accessor {}) is out of range: {} elements of {} bytes from offset {} "
          "do not fit in buffer view {}, which has {} bytes",
          what, index, acc.count, stride, acc.byteOffset, acc.bufferView, view.byteLength));
    return {buffer.data.data() + view.byteOffset + acc.byteOffset, std::size_t(stride)};
  }

  // Reads an accessor into floats (normalised integers mapped to [0,1] / [-1,1]); every float
  // must be finite.
  std::vector<float> read_floats(int index, int expected_components, const std::string& what) {
    const tinygltf::Accessor& acc = accessor(index, what);
    const int comps = components(acc, index, what);
    if (expected_components > 0 && comps != expected_components)
      fail(fmt::format("{} (accessor {}) has {} components, expected {}", what, index, comps,
                       expected_components));
    const std::size_t n = values_of(acc, comps, index, what);
    const Span span = locate(acc, comps, index, what);
    std::vector<float> out(n, 0.0f);
    if (!span.data) return out;  // no buffer view: all zeros (glTF rule)
    for (std::size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = span.data + i * span.stride;
      for (int c = 0; c < comps; ++c) {
        const float v = component(p, c, acc);
        if (!std::isfinite(v))
          fail(fmt::format("{} (accessor {}) holds a non-finite value at element {}", what, index,
                           i));
        out[i * comps + c] = v;
      }
    }
    return out;
  }

  std::vector<uint32_t> read_uints(int index, const std::string& what) {
    const tinygltf::Accessor& acc = accessor(index, what);
    const int comps = components(acc, index, what);
    const int size = tinygltf::GetComponentSizeInBytes(acc.componentType);
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(fmt::format("{} (accessor {}) must hold unsigned integers", what, index));
    const std::size_t n = values_of(acc, comps, index, what);
    const Span span = locate(acc, comps, index, what);
    std::vector<uint32_t> out(n, 0u);
    if (!span.data) return out;
    for (std::size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = span.data + i * span.stride;
      for (int c = 0; c < comps; ++c) {
        const unsigned char* q = p + c * size;
        uint32_t v = *q;
        if (size == 2) {
          uint16_t u;
          std::memcpy(&u, q, 2);
          v = u;
        } else if (size == 4) {
          std::memcpy(&v, q, 4);
        }
        out[i * comps + c] = v;
      }
    }
    return out;
  }

  float component(const unsigned char* p, int c, const tinygltf::Accessor& acc) const {
    switch (acc.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p + 4 * c, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        const float v = p[c];
        return acc.normalized ? v / 255.0f : v;
      }
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const float v = float(int8_t(p[c]));
        return acc.normalized ? std::max(v / 127.0f, -1.0f) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return acc.normalized ? v / 65535.0f : float(v);
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return acc.normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p + 4 * c, 4);
        return float(v);
      }
      default:
        fail(fmt::format("unsupported accessor component type {}", acc.componentType));
    }
  }

  template <typename V>
  std::vector<V> read_vecs(int index, const std::string& what) {
    constexpr int n = V::length();
    const std::vector<float> f = read_floats(index, n, what);
    std::vector<V> out(f.size() / n);
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < n; ++c) out[i][c] = f[i * n + c];
    return out;
  }

  // ---- Materials and textures ----

  void load_textures_and_materials(Scene& s) {
    texture_map_.assign(m_.textures.size(), -1);
    for (std::size_t mi = 0; mi < m_.materials.size(); ++mi) {
      const tinygltf::Material& mat = m_.materials[mi];
      scene::Material out;
      out.name = mat.name;
      const auto& f = mat.pbrMetallicRoughness.baseColorFactor;
      if (f.size() == 4) {
        for (int c = 0; c < 4; ++c)
          if (!finite_float(f[c]))
            fail(fmt::format("material {} ('{}') has a non-finite baseColorFactor", mi,
                             echo(mat.name)));
        out.base_color = glm::vec4(f[0], f[1], f[2], f[3]);
      }
      const int tex = mat.pbrMetallicRoughness.baseColorTexture.index;
      if (tex >= 0) {
        out.base_color_texture = base_color_texture(s, tex, mat.name);
        out.texcoord = mat.pbrMetallicRoughness.baseColorTexture.texCoord;
      }
      s.materials.push_back(std::move(out));
    }
  }

  int base_color_texture(Scene& s, int tex, const std::string& material) {
    if (std::size_t(tex) >= m_.textures.size())
      fail(fmt::format("material '{}' refers to texture {}, but the file has {}", echo(material),
                       tex, m_.textures.size()));
    if (texture_map_[tex] >= 0) return texture_map_[tex];
    const tinygltf::Texture& t = m_.textures[tex];
    if (t.source < 0 || std::size_t(t.source) >= m_.images.size())
      fail(fmt::format("texture {} refers to image {}, but the file has {}", tex, t.source,
                       m_.images.size()));
    const tinygltf::Image& encoded = m_.images[t.source];
    const std::string name =
        encoded.uri.empty() ? fmt::format("image {}", t.source) : echo(encoded.uri);
    if (encoded.width <= 0 || encoded.height <= 0 || encoded.image.empty())
      fail(fmt::format("texture {} ({}) did not decode", tex, name));
    const auto pixels = checked_mul<int64_t>(encoded.width, encoded.height);
    const auto total = pixels ? checked_add<int64_t>(texture_pixels_, *pixels) : std::nullopt;
    if (!total || *total > kMaxTexturePixels)
      fail(
          fmt::format("texture {} ({}, {}x{}): the scene's base-colour textures would hold more "
                      "than {} pixels",
                      tex, name, encoded.width, encoded.height, kMaxTexturePixels));
    texture_pixels_ = *total;
    // Decoded here, to 8 or 16 bits RGBA, by tinygltf's own decoder.
    tinygltf::Image img;
    img.name = encoded.name;
    std::string err, warn;
    if (encoded.image.size() > std::size_t(INT32_MAX) ||
        !tinygltf::LoadImageData(&img, t.source, &err, &warn, encoded.width, encoded.height,
                                 encoded.image.data(), int(encoded.image.size()), nullptr))
      fail(fmt::format("texture {} ({}) did not decode", tex, name));
    const int comps = img.component;
    const int bytes = img.bits == 16 ? 2 : 1;
    if (img.width != encoded.width || img.height != encoded.height || comps <= 0 || comps > 4 ||
        img.image.size() < std::size_t(img.width) * img.height * comps * bytes)
      fail(fmt::format("texture {} ({}) did not decode: too little pixel data", tex, name));
    scene::Texture out;
    out.rgba.reset(img.width, img.height, 4);
    for (int y = 0; y < img.height; ++y) {
      float* row = out.rgba.row(y);
      for (int x = 0; x < img.width; ++x) {
        float v[4] = {0, 0, 0, 1};
        for (int c = 0; c < comps; ++c) {
          const std::size_t i = (std::size_t(y) * img.width + x) * comps + c;
          if (bytes == 2) {
            uint16_t u;
            std::memcpy(&u, img.image.data() + 2 * i, 2);
            v[c] = u / 65535.0f;
          } else {
            v[c] = img.image[i] / 255.0f;
          }
        }
        if (comps < 3) {  // grey (+ alpha)
          if (comps == 2) v[3] = v[1];
          v[1] = v[2] = v[0];
        }
        for (int c = 0; c < 3; ++c) row[4 * x + c] = srgb_to_linear(v[c]);
        row[4 * x + 3] = v[3];
      }
    }
    if (t.sampler >= 0 && std::size_t(t.sampler) < m_.samplers.size()) {
      auto wrap = [](int mode) {
        switch (mode) {
          case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
            return scene::Texture::Wrap::kClamp;
          case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
            return scene::Texture::Wrap::kMirror;
          default:
            return scene::Texture::Wrap::kRepeat;
        }
      };
      out.wrap_s = wrap(m_.samplers[t.sampler].wrapS);
      out.wrap_t = wrap(m_.samplers[t.sampler].wrapT);
    }
    s.textures.push_back(std::move(out));
    texture_map_[tex] = int(s.textures.size()) - 1;
    return texture_map_[tex];
  }

  // ---- Meshes ----

  // Adds n to a running total, failing once it passes `limit`.
  void charge(int64_t& total, uint64_t n, int64_t limit, const std::string& what) const {
    const auto sum = n <= uint64_t(limit) ? checked_add<int64_t>(total, int64_t(n)) : std::nullopt;
    if (!sum || *sum > limit) fail(fmt::format("{} (more than {})", what, limit));
    total = *sum;
  }

  void load_meshes(Scene& s) {
    mesh_vertices_.assign(m_.meshes.size(), 0);
    mesh_triangles_.assign(m_.meshes.size(), 0);
    for (std::size_t mi = 0; mi < m_.meshes.size(); ++mi) {
      const tinygltf::Mesh& mesh = m_.meshes[mi];
      scene::Mesh out;
      out.name = mesh.name;
      for (double w : mesh.weights) {
        if (!finite_float(w))
          fail(fmt::format("mesh {} ('{}') has a non-finite morph weight", mi, echo(mesh.name)));
        out.weights.push_back(float(w));
      }
      for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
        const tinygltf::Primitive& prim = mesh.primitives[pi];
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN)
          continue;  // points and lines draw nothing in a guide pass
        const std::string where =
            fmt::format("mesh {} ('{}') primitive {}", mi, echo(mesh.name), pi);
        auto attr = [&](const char* name) {
          auto it = prim.attributes.find(name);
          return it == prim.attributes.end() ? -1 : it->second;
        };
        if (attr("POSITION") < 0) fail(where + " has no POSITION attribute");
        scene::Primitive p;
        p.positions = read_vecs<glm::vec3>(attr("POSITION"), where + " POSITION");
        const std::size_t nv = p.positions.size();
        charge(vertices_, nv, kMaxVertices, where + " takes the file past its vertex limit");
        mesh_vertices_[mi] += int64_t(nv);
        auto check_count = [&](std::size_t n, const char* name) {
          if (n != nv)
            fail(fmt::format("{} {} has {} elements, POSITION has {}", where, name, n, nv));
        };
        if (attr("NORMAL") >= 0) {
          p.normals = read_vecs<glm::vec3>(attr("NORMAL"), where + " NORMAL");
          check_count(p.normals.size(), "NORMAL");
        }
        if (attr("TEXCOORD_0") >= 0) {
          p.uvs = read_vecs<glm::vec2>(attr("TEXCOORD_0"), where + " TEXCOORD_0");
          check_count(p.uvs.size(), "TEXCOORD_0");
        }
        if (attr("JOINTS_0") >= 0 && attr("WEIGHTS_0") >= 0) {
          const std::vector<uint32_t> j = read_uints(attr("JOINTS_0"), where + " JOINTS_0");
          if (j.size() != nv * 4)
            fail(fmt::format("{} JOINTS_0 has {} values, expected 4 for each of {} vertices", where,
                             j.size(), nv));
          p.weights = read_vecs<glm::vec4>(attr("WEIGHTS_0"), where + " WEIGHTS_0");
          check_count(p.weights.size(), "WEIGHTS_0");
          p.joints.resize(nv);
          for (std::size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 4; ++c) {
              if (j[4 * v + c] >= uint32_t(kMaxSkinJoints))
                fail(fmt::format("{} JOINTS_0 holds joint {}, more than a skin can have", where,
                                 j[4 * v + c]));
              p.joints[v][c] = uint16_t(j[4 * v + c]);
            }
        }
        if (prim.targets.size() > std::size_t(kMaxMorphTargets))
          fail(fmt::format("{} has {} morph targets (at most {})", where, prim.targets.size(),
                           kMaxMorphTargets));
        for (std::size_t ti = 0; ti < prim.targets.size(); ++ti) {
          scene::MorphTarget target;
          for (const auto& [name, index] : prim.targets[ti]) {
            const std::string what = fmt::format("{} morph target {} {}", where, ti, echo(name));
            if (name == "POSITION") {
              target.positions = read_vecs<glm::vec3>(index, what);
              check_count(target.positions.size(), "morph POSITION");
            } else if (name == "NORMAL") {
              target.normals = read_vecs<glm::vec3>(index, what);
              check_count(target.normals.size(), "morph NORMAL");
            }
          }
          p.targets.push_back(std::move(target));
        }
        std::vector<uint32_t> idx;
        if (prim.indices >= 0) {
          idx = read_uints(prim.indices, where + " indices");
        } else {
          idx.resize(nv);
          for (std::size_t i = 0; i < nv; ++i) idx[i] = uint32_t(i);
        }
        for (uint32_t i : idx)
          if (i >= nv) fail(fmt::format("{} has index {} but only {} vertices", where, i, nv));
        const std::size_t tris = mode == TINYGLTF_MODE_TRIANGLES
                                     ? idx.size() / 3
                                     : std::max<std::size_t>(idx.size(), 2) - 2;
        charge(triangles_, tris, kMaxTriangles, where + " takes the file past its triangle limit");
        mesh_triangles_[mi] += int64_t(tris);
        p.indices = triangles(idx, mode);
        if (prim.material >= 0 && std::size_t(prim.material) >= m_.materials.size())
          fail(fmt::format("{} refers to material {}, but the file has {}", where, prim.material,
                           m_.materials.size()));
        p.material = prim.material < 0 ? -1 : prim.material;
        out.primitives.push_back(std::move(p));
      }
      s.meshes.push_back(std::move(out));
    }
  }

  static std::vector<uint32_t> triangles(const std::vector<uint32_t>& idx, int mode) {
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      std::vector<uint32_t> out(idx.begin(), idx.begin() + idx.size() / 3 * 3);
      return out;
    }
    std::vector<uint32_t> out;
    if (idx.size() >= 3) out.reserve(3 * (idx.size() - 2));
    for (std::size_t i = 2; i < idx.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        out.insert(out.end(), {idx[0], idx[i - 1], idx[i]});
      } else if (i % 2 == 0) {
        out.insert(out.end(), {idx[i - 2], idx[i - 1], idx[i]});
      } else {
        out.insert(out.end(), {idx[i - 1], idx[i - 2], idx[i]});
      }
    }
    return out;
  }

  // ---- Skins and cameras ----

  void load_skins(Scene& s) {
    for (std::size_t si = 0; si < m_.skins.size(); ++si) {
      const tinygltf::Skin& skin = m_.skins[si];
      scene::Skin out;
      out.name = skin.name;
      if (skin.joints.size() > std::size_t(kMaxSkinJoints))
        fail(fmt::format("skin {} has {} joints (at most {})", si, skin.joints.size(),
                         kMaxSkinJoints));
      for (int j : skin.joints) {
        if (j < 0 || std::size_t(j) >= m_.nodes.size())
          fail(fmt::format("skin {} refers to node {}, but the file has {}", si, j,
                           m_.nodes.size()));
        out.joints.push_back(j);
      }
      if (skin.inverseBindMatrices >= 0) {
        const std::vector<float> f = read_floats(skin.inverseBindMatrices, 16,
                                                 fmt::format("skin {} inverseBindMatrices", si));
        if (f.size() / 16 < out.joints.size())
          fail(fmt::format("skin {} has {} inverse bind matrices for {} joints", si, f.size() / 16,
                           out.joints.size()));
        for (std::size_t j = 0; j < out.joints.size(); ++j) {
          glm::mat4 m;
          std::memcpy(&m[0][0], f.data() + 16 * j, 16 * sizeof(float));  // column-major both
          out.inverse_bind.push_back(m);
        }
      } else {
        out.inverse_bind.assign(out.joints.size(), glm::mat4(1.0f));
      }
      s.skins.push_back(std::move(out));
    }
  }

  void load_cameras(Scene& s) {
    for (std::size_t ci = 0; ci < m_.cameras.size(); ++ci) {
      const tinygltf::Camera& c = m_.cameras[ci];
      scene::CameraDef def;
      def.name = c.name;
      def.perspective = c.type != "orthographic";
      bool ok;
      if (def.perspective) {
        ok = finite_float(c.perspective.yfov) && c.perspective.yfov > 0.0 &&
             c.perspective.yfov < 3.14159 && finite_float(c.perspective.znear) &&
             c.perspective.znear > 0.0;
        def.yfov = float(c.perspective.yfov);
        def.znear = float(c.perspective.znear);
      } else {
        ok = finite_float(c.orthographic.xmag) && c.orthographic.xmag != 0.0 &&
             finite_float(c.orthographic.ymag) && c.orthographic.ymag != 0.0 &&
             finite_float(c.orthographic.znear) && c.orthographic.znear >= 0.0;
        def.xmag = float(c.orthographic.xmag);
        def.ymag = float(c.orthographic.ymag);
        def.znear = float(c.orthographic.znear);
      }
      if (!ok)
        fail(fmt::format("camera {} ('{}') has an invalid field of view, magnification or znear",
                         ci, echo(c.name)));
      s.cameras.push_back(def);
    }
  }

  // ---- Nodes: the hierarchy must be a forest ----

  void load_nodes(Scene& s) {
    const int n = int(m_.nodes.size());
    s.nodes.resize(n);
    for (int i = 0; i < n; ++i) {
      const tinygltf::Node& in = m_.nodes[i];
      scene::Node& node = s.nodes[i];
      node.name = in.name;
      auto finite_all = [&](const std::vector<double>& v, const char* what) {
        for (double d : v)
          if (!finite_float(d))
            fail(fmt::format("node {} ('{}') has a non-finite {}", i, echo(in.name), what));
      };
      finite_all(in.translation, "translation");
      finite_all(in.rotation, "rotation");
      finite_all(in.scale, "scale");
      finite_all(in.matrix, "matrix");
      finite_all(in.weights, "morph weight");
      if (in.translation.size() == 3)
        node.translation = glm::vec3(in.translation[0], in.translation[1], in.translation[2]);
      if (in.rotation.size() == 4)
        node.rotation = glm::quat(float(in.rotation[3]), float(in.rotation[0]),
                                  float(in.rotation[1]), float(in.rotation[2]));
      if (in.scale.size() == 3) node.scale = glm::vec3(in.scale[0], in.scale[1], in.scale[2]);
      if (in.matrix.size() == 16) {
        node.has_matrix = true;
        for (int k = 0; k < 16; ++k) node.matrix[k / 4][k % 4] = float(in.matrix[k]);
      }
      auto check_ref = [&](int ref, std::size_t count, const char* what) {
        if (ref >= 0 && std::size_t(ref) >= count)
          fail(fmt::format("node {} refers to {} {}, but the file has {}", i, what, ref, count));
      };
      check_ref(in.mesh, s.meshes.size(), "mesh");
      check_ref(in.skin, s.skins.size(), "skin");
      check_ref(in.camera, s.cameras.size(), "camera");
      node.mesh = std::max(in.mesh, -1);
      node.skin = std::max(in.skin, -1);
      node.camera = std::max(in.camera, -1);
      for (double w : in.weights) node.weights.push_back(float(w));
      for (int c : in.children) {
        if (c < 0 || c >= n)
          fail(fmt::format("node {} lists child {}, but the file has {} nodes", i, c, n));
        if (c == i) fail(fmt::format("node {} lists itself as a child", i));
        if (s.nodes[c].parent >= 0)
          fail(
              fmt::format("node {} has two parents (nodes {} and {}); the node hierarchy must "
                          "be a tree",
                          c, s.nodes[c].parent, i));
        node.children.push_back(c);
        s.nodes[c].parent = i;
      }
    }
    check_no_cycles(s);
    // Joint indices must stay inside the skin the mesh is drawn with.
    for (int i = 0; i < n; ++i) {
      const scene::Node& node = s.nodes[i];
      if (node.mesh < 0 || node.skin < 0) continue;
      const std::size_t joints = s.skins[node.skin].joints.size();
      for (const auto& p : s.meshes[node.mesh].primitives)
        for (const auto& j : p.joints)
          for (int c = 0; c < 4; ++c)
            if (j[c] >= joints)
              fail(fmt::format("mesh {} uses joint {} but skin {} has {} joints", node.mesh, j[c],
                               node.skin, joints));
    }
    const int scene_index = m_.defaultScene >= 0 ? m_.defaultScene : 0;
    if (std::size_t(scene_index) < m_.scenes.size()) {
      std::vector<char> listed(n, 0);
      for (int r : m_.scenes[scene_index].nodes) {
        if (r < 0 || r >= n)
          fail(fmt::format("scene {} refers to node {}, but the file has {} nodes", scene_index, r,
                           n));
        if (listed[r]) fail(fmt::format("scene {} lists node {} twice", scene_index, r));
        listed[r] = 1;
      }
      // Exporters do list child nodes as scene roots (cakeBirthday.glb does). A listed node
      // below another listed node is drawn through that one, so it is not a root of its own:
      // nothing is drawn twice.
      std::vector<char> below_listed(n, 0);
      std::vector<int> stack;
      for (int i = 0; i < n; ++i)
        if (s.nodes[i].parent < 0) stack.push_back(i);
      while (!stack.empty()) {
        const int i = stack.back();
        stack.pop_back();
        for (int c : s.nodes[i].children) {
          below_listed[c] = below_listed[i] || listed[i];
          stack.push_back(c);
        }
      }
      for (int r : m_.scenes[scene_index].nodes)
        if (!below_listed[r]) s.roots.push_back(r);
    } else {
      for (int i = 0; i < n; ++i)
        if (s.nodes[i].parent < 0) s.roots.push_back(i);
    }
  }

  // With one parent per node, the hierarchy has a cycle exactly when walking up from some node
  // never reaches a root. Each node is walked once: O(nodes).
  void check_no_cycles(const Scene& s) const {
    const int n = int(s.nodes.size());
    std::vector<char> state(n, 0);  // 0: not seen, 1: on the current walk, 2: reaches a root
    std::vector<int> walk;
    for (int i = 0; i < n; ++i) {
      walk.clear();
      int j = i;
      while (j >= 0 && state[j] == 0) {
        state[j] = 1;
        walk.push_back(j);
        j = s.nodes[j].parent;
      }
      if (j >= 0 && state[j] == 1)
        fail(fmt::format("node {} is its own ancestor: the node hierarchy has a cycle", j));
      for (int k : walk) state[k] = 2;
    }
  }

  // ---- Animations ----

  void load_animations(Scene& s) {
    for (std::size_t ai = 0; ai < m_.animations.size(); ++ai) {
      const tinygltf::Animation& anim = m_.animations[ai];
      scene::Animation out;
      out.name = anim.name.empty() ? fmt::format("animation{}", ai) : anim.name;
      const std::string label = fmt::format("animation {} ('{}')", ai, echo(out.name));
      out.start = 1e30f;
      out.end = -1e30f;
      for (const auto& ch : anim.channels) {
        if (ch.sampler < 0 || std::size_t(ch.sampler) >= anim.samplers.size())
          fail(fmt::format("{} channel refers to sampler {}", label, ch.sampler));
        if (ch.target_node < 0 || std::size_t(ch.target_node) >= m_.nodes.size())
          fail(fmt::format("{} channel targets node {}", label, ch.target_node));
      }
      for (std::size_t si = 0; si < anim.samplers.size(); ++si) {
        const tinygltf::AnimationSampler& in = anim.samplers[si];
        const std::string what = fmt::format("{} sampler {}", label, si);
        scene::AnimSampler smp;
        smp.times = read_floats(in.input, 1, what + " input");
        if (smp.times.empty()) fail(what + " has no keyframes");
        for (std::size_t k = 0; k < smp.times.size(); ++k) {
          if (!(std::abs(smp.times[k]) <= kMaxKeyTime))
            fail(fmt::format("{} has key time {} s (key times must be finite and within ±{} s)",
                             what, smp.times[k], kMaxKeyTime));
          if (k > 0 && !(smp.times[k] >= smp.times[k - 1]))
            fail(fmt::format("{} has key times that decrease ({} s after {} s)", what, smp.times[k],
                             smp.times[k - 1]));
        }
        smp.values = read_floats(in.output, 0, what + " output");
        smp.interpolation = in.interpolation == "STEP"          ? scene::Interpolation::kStep
                            : in.interpolation == "CUBICSPLINE" ? scene::Interpolation::kCubicSpline
                                                                : scene::Interpolation::kLinear;
        const std::size_t keys =
            smp.times.size() * (smp.interpolation == scene::Interpolation::kCubicSpline ? 3 : 1);
        if (smp.values.size() % keys != 0 || smp.values.empty())
          fail(fmt::format("{} output has {} values for {} keys", what, smp.values.size(), keys));
        if (smp.values.size() / keys > std::size_t(kMaxMorphTargets))
          fail(fmt::format("{} output has {} values per key (at most {})", what,
                           smp.values.size() / keys, kMaxMorphTargets));
        smp.components = int(smp.values.size() / keys);
        out.start = std::min(out.start, smp.times.front());
        out.end = std::max(out.end, smp.times.back());
        out.samplers.push_back(std::move(smp));
      }
      for (const auto& ch : anim.channels) {
        scene::AnimChannel c;
        c.node = ch.target_node;
        c.sampler = ch.sampler;
        int need = 3;
        if (ch.target_path == "translation") {
          c.path = scene::AnimPath::kTranslation;
        } else if (ch.target_path == "rotation") {
          c.path = scene::AnimPath::kRotation;
          need = 4;
        } else if (ch.target_path == "scale") {
          c.path = scene::AnimPath::kScale;
        } else if (ch.target_path == "weights") {
          c.path = scene::AnimPath::kWeights;
          need = -1;
        } else {
          continue;  // extension paths (KHR_animation_pointer) are not ours
        }
        const int comps = out.samplers[ch.sampler].components;
        if (need > 0 && comps != need)
          fail(fmt::format("{} {} channel has {} components per key, expected {}", label,
                           ch.target_path, comps, need));
        if (s.nodes[c.node].has_matrix)
          fail(fmt::format("{} animates node {}, which is given by a matrix", label, c.node));
        out.channels.push_back(c);
      }
      if (out.samplers.empty()) out.start = out.end = 0.0f;
      s.animations.push_back(std::move(out));
    }
  }

  // ---- What is drawn ----

  // Every drawn instance of a mesh is posed and rasterised separately each frame, so the drawn
  // totals are bounded as well as the stored ones. The hierarchy is a forest: one visit a node.
  void check_drawn_size(const Scene& s) const {
    int64_t vertices = 0, triangles = 0;
    std::vector<int> stack = s.roots;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const scene::Node& node = s.nodes[i];
      if (node.mesh >= 0) {
        charge(vertices, uint64_t(mesh_vertices_[node.mesh]), kMaxVertices,
               "the scene's nodes draw too many vertices, counting each instance of a mesh");
        charge(triangles, uint64_t(mesh_triangles_[node.mesh]), kMaxTriangles,
               "the scene's nodes draw too many triangles, counting each instance of a mesh");
      }
      stack.insert(stack.end(), node.children.begin(), node.children.end());
    }
  }

  void check_drawable(const Scene& s) const {
    std::vector<int> stack = s.roots;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const scene::Node& node = s.nodes[i];
      if (node.mesh >= 0)
        for (const auto& p : s.meshes[node.mesh].primitives)
          if (!p.indices.empty()) return;
      stack.insert(stack.end(), node.children.begin(), node.children.end());
    }
    fail("empty scene: no triangle mesh to draw");
  }

  std::string path_;
  const tinygltf::Model& m_;
  std::vector<int> texture_map_;
  uint64_t values_read_ = 0;
  int64_t vertices_ = 0, triangles_ = 0, texture_pixels_ = 0;
  std::vector<int64_t> mesh_vertices_, mesh_triangles_;
};

Scene load_bytes(std::string_view bytes, const std::string& name, const fs::path& root,
                 const std::string& base_dir, const GltfOptions& options) {
  if (bytes.size() > uint64_t(kMaxFileBytes))
    throw Error(name, fmt::format("is {} bytes; a scene file may have at most {}", bytes.size(),
                                  kMaxFileBytes));
  // Sniff the magic rather than trust the extension.
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::size_t length = bytes.size();
  check_json_shape(binary ? glb_json_chunk(bytes, name, length) : bytes, name);

  tinygltf::Model model;
  tinygltf::TinyGLTF gltf;
  FileAccess files;
  files.root = root;
  files.allow_outside = options.allow_outside_paths;
  gltf.SetFsCallbacks({&file_exists, &expand_path, &read_file, &write_file, &files});
  ImageAccess images;
  images.model = &model;
  gltf.SetImageLoader(&keep_encoded_image, &images);
  std::string err, warn;
  const bool ok =
      binary
          ? gltf.LoadBinaryFromMemory(&model, &err, &warn,
                                      reinterpret_cast<const unsigned char*>(bytes.data()),
                                      unsigned(length), base_dir)
          : gltf.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(length), base_dir);
  // Refusals come first: tinygltf reports them only as "file not found" or a warning.
  if (!files.refused.empty()) throw Error(name, files.refused);
  if (!images.error.empty()) throw Error(name, images.error);
  if (!ok || !err.empty())
    throw Error(name,
                "not a valid glTF file: " + one_line(err.empty() ? "could not be parsed" : err));
  // Extensions the file cannot be drawn without: only those whose data we read are accepted.
  for (const std::string& ext_name : model.extensionsRequired) {
    if (ext_name != "KHR_mesh_quantization" && ext_name != "KHR_materials_unlit" &&
        ext_name != "KHR_texture_transform" && ext_name.rfind("KHR_materials_", 0) != 0)
      throw Error(name, fmt::format("requires the glTF extension {}, which is not supported",
                                    echo(ext_name)));
  }
  return Loader(name, model).load();
}

fs::path canonical_folder(const fs::path& dir) {
  std::error_code ec;
  const fs::path abs = fs::absolute(dir.empty() ? fs::path(".") : dir, ec);
  const fs::path real = ec ? fs::path() : fs::weakly_canonical(abs, ec);
  return ec ? fs::path() : real;
}

}  // namespace

Scene load_gltf(const std::string& path, const GltfOptions& options) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error(path, "no such file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(path, "cannot be read");
  if (size > uint64_t(kMaxFileBytes))
    throw Error(path,
                fmt::format("is {} bytes; a scene file may have at most {}", size, kMaxFileBytes));
  std::string bytes(size, '\0');
  std::ifstream in(path, std::ios::binary);
  if (!in.read(bytes.data(), std::streamsize(size))) throw Error(path, "cannot be read");
  const fs::path dir = fs::path(path).parent_path();
  return load_bytes(bytes, path, canonical_folder(dir), dir.string(), options);
}

Scene load_gltf_from_memory(std::string_view bytes, const std::string& name,
                            const std::string& base_dir, const GltfOptions& options) {
  return load_bytes(bytes, name, base_dir.empty() ? fs::path() : canonical_folder(base_dir),
                    base_dir, options);
}

}  // namespace emaki::io
