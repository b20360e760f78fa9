// tinygltf's callbacks (see gltf_internal.h): the only way the parser reaches files and image
// bytes, so every refusal of an outside path, a special file or an oversized image is here.
#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <fstream>

#include "core/error.h"
#include "core/limits.h"
#include "io/gltf_internal.h"

namespace emaki::io::gltf_detail {

namespace {

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

}  // namespace

tinygltf::FsCallbacks file_callbacks(FileAccess* files) {
  return {&file_exists, &expand_path, &read_file, &write_file, files};
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

}  // namespace emaki::io::gltf_detail
