// Reading glTF accessors (Loader members, see gltf_internal.h). Every element an accessor names
// is located with overflow-checked arithmetic inside its buffer view and buffer before a byte of
// it is read, and every value read is charged to kMaxAccessorValues.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "core/limits.h"
#include "io/gltf_internal.h"

namespace emaki::io::gltf_detail {

const tinygltf::Accessor& Loader::accessor(int index, const std::string& what) const {
  if (index < 0 || std::size_t(index) >= m_.accessors.size())
    fail(fmt::format("{} refers to accessor {}, but the file has {}", what, index,
                     m_.accessors.size()));
  const tinygltf::Accessor& acc = m_.accessors[index];
  if (acc.sparse.isSparse)
    fail(fmt::format("{} (accessor {}) is sparse, which is not supported", what, index));
  return acc;
}

int Loader::components(const tinygltf::Accessor& acc, int index, const std::string& what) const {
  const int comps = tinygltf::GetNumComponentsInType(acc.type);
  const int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
  if (comps <= 0 || comps > 16 || csize <= 0 || csize > 8)
    fail(fmt::format("{} (accessor {}) has an invalid type", what, index));
  return comps;
}

// The number of values an accessor yields, charged to the file's kMaxAccessorValues.
std::size_t Loader::values_of(const tinygltf::Accessor& acc, int comps, int index,
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
Loader::Span Loader::locate(const tinygltf::Accessor& acc, int comps, int index,
                            const std::string& what) const {
  if (acc.bufferView < 0) {
    if (acc.count > uint64_t(kMaxZeroAccessorElements))
      fail(
          fmt::format("{} (accessor {}) has no buffer view: its {} elements would all be zero "
                      "(at most {} allowed)",
                      what, index, acc.count, kMaxZeroAccessorElements));
    return {};
  }
  if (std::size_t(acc.bufferView) >= m_.bufferViews.size())
    fail(fmt::format("{} (accessor {}) refers to buffer view {}, but the file has {}", what, index,
                     acc.bufferView, m_.bufferViews.size()));
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
std::vector<float> Loader::read_floats(int index, int expected_components,
                                       const std::string& what) {
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
        fail(
            fmt::format("{} (accessor {}) holds a non-finite value at element {}", what, index, i));
      out[i * comps + c] = v;
    }
  }
  return out;
}

std::vector<uint32_t> Loader::read_uints(int index, const std::string& what) {
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

float Loader::component(const unsigned char* p, int c, const tinygltf::Accessor& acc) const {
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

// Adds n to a running total, failing once it passes `limit`.
void Loader::charge(int64_t& total, uint64_t n, int64_t limit, const std::string& what) const {
  const auto sum = n <= uint64_t(limit) ? checked_add<int64_t>(total, int64_t(n)) : std::nullopt;
  if (!sum || *sum > limit) fail(fmt::format("{} (more than {})", what, limit));
  total = *sum;
}

}  // namespace emaki::io::gltf_detail
