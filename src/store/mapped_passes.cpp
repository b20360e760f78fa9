#include "store/mapped_passes.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <vector>

#include "core/check.h"
#include "io/temp_file.h"
#include "render/passes.h"

namespace emaki::io {

namespace {

constexpr char kMagic[8] = {'e', 'm', 'k', 'p', 'a', 's', 's', '1'};
struct FileHeader {
  char magic[8];
  int32_t width, height, channels, pad;
  int64_t stride;  // floats between rows
  char zero[32];
};
static_assert(sizeof(FileHeader) == kRowAlign);

// The open file `fd`'s header and size when they describe width x height passes.
bool check_header(int fd, int width, int height, FileHeader& h, struct stat& st) {
  return ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
         ::pread(fd, &h, sizeof h, 0) == ssize_t(sizeof h) &&
         std::memcmp(h.magic, kMagic, sizeof kMagic) == 0 && h.width == width &&
         h.height == height && h.channels == render::kChannelCount &&
         h.stride >= int64_t(width) * h.channels &&
         h.stride % int64_t(kRowAlign / sizeof(float)) == 0 &&
         uint64_t(st.st_size) == sizeof h + uint64_t(h.stride) * uint64_t(height) * 4;
}

void unmap(void* block, std::size_t bytes) {
  ::munmap(block, bytes);
}

}  // namespace

void write_mapped_passes(const std::string& path, ImageView<const float> passes) {
  CHECK_EQ(passes.channels, render::kChannelCount);
  const std::size_t row = std::size_t(passes.width) * std::size_t(passes.channels);
  const std::size_t stride = (row * sizeof(float) + kRowAlign - 1) / kRowAlign * kRowAlign / 4;
  FileHeader h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.width = passes.width, h.height = passes.height, h.channels = passes.channels;
  h.stride = int64_t(stride);
  TempFile file(path, path);
  file.write(&h, sizeof h);
  if (passes.stride == std::ptrdiff_t(stride)) {
    // Rows padded as the file pads them: the image in one write, padding as the image holds it
    // (nothing reads it).
    file.write(passes.data, stride * sizeof(float) * std::size_t(passes.height));
  } else {
    std::vector<float> padded(stride, 0.f);
    for (int y = 0; y < passes.height; ++y) {
      std::memcpy(padded.data(), passes.row(y), row * sizeof(float));
      file.write(padded.data(), stride * sizeof(float));
    }
  }
  file.commit();
}

std::optional<Image<float>> map_passes(const std::string& path, int width, int height) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  struct stat st {};
  FileHeader h{};
  const bool ok = check_header(fd, width, height, h, st);
  void* block =
      ok ? ::mmap(nullptr, std::size_t(st.st_size), PROT_READ | PROT_WRITE, MAP_PRIVATE, fd, 0)
         : MAP_FAILED;
  ::close(fd);
  if (block == MAP_FAILED) return std::nullopt;
  float* data = reinterpret_cast<float*>(static_cast<char*>(block) + sizeof h);
  return Image<float>::adopt(data, width, height, h.channels, std::ptrdiff_t(h.stride), block,
                             std::size_t(st.st_size), unmap);
}

bool mapped_passes_complete(const std::string& path, int width, int height) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  FileHeader h{};
  const bool ok = check_header(fd, width, height, h, st);
  ::close(fd);
  return ok;
}

}  // namespace emaki::io
