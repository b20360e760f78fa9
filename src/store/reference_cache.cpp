#include "store/reference_cache.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <optional>
#include <vector>

#include "core/error.h"
#include "core/fnv.h"
#include "io/temp_file.h"
#include "render/passes.h"
#include "store/output_store.h"
#include "store/settings_manifests.h"

namespace emaki::io {

namespace fs = std::filesystem;

namespace {

std::string folder_of(const std::string& output_folder) {
  return (fs::path(output_folder) / "references").string();
}

// FNV-1a over the pixels' 64-bit words in four interleaved lanes, folded together at the end.
// Every layer task checks the 105 MB of a 1200x912 painting's passes: one chain over 32-bit
// words (pipeline::value_digest) waits on each multiply, about a quarter of a layer task's fixed
// cost; four independent chains keep the multiplier busy.
uint64_t pixels_digest(ImageView<const float> passes) {
  uint64_t lane[4] = {kFnvOffset, kFnvOffset ^ 1, kFnvOffset ^ 2, kFnvOffset ^ 3};
  const auto add = [](uint64_t h, uint64_t w) { return (h ^ w) * kFnvPrime; };
  const std::size_t n = std::size_t(passes.width) * std::size_t(passes.channels);
  for (int y = 0; y < passes.height; ++y) {
    const unsigned char* row = reinterpret_cast<const unsigned char*>(passes.row(y));
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      uint64_t w[4];
      std::memcpy(w, row + i * 4, sizeof w);
      for (int k = 0; k < 4; ++k) lane[k] = add(lane[k], w[k]);
    }
    for (; i < n; ++i) {
      uint32_t w;
      std::memcpy(&w, row + i * 4, 4);
      lane[0] = add(lane[0], w);
    }
  }
  uint64_t h = kFnvOffset;
  for (const int32_t v : {passes.width, passes.height, passes.channels}) h = add(h, uint32_t(v));
  for (const uint64_t l : lane) h = add(h, l);
  return h;
}

std::string digest_text(ImageView<const float> passes) {
  return fmt::format("{:016x}\n", pixels_digest(passes));
}

// KEY.passes: a 64-byte header, then the image's rows exactly as Image<float> holds them (padded
// to kRowAlign), so that a read maps the file and uses it in place: no decoding, no copy, and no
// fresh pages to fault in (a farm's every layer task reads the reference; 1200x912x24 floats
// are 105 MB).
constexpr char kMagic[8] = {'e', 'm', 'k', 'p', 'a', 's', 's', '1'};
struct FileHeader {
  char magic[8];
  int32_t width, height, channels, pad;
  int64_t stride;  // floats between rows
  char zero[32];
};
static_assert(sizeof(FileHeader) == kRowAlign);

std::string pixels_path(const std::string& dir, const std::string& key) {
  return dir + "/" + key + ".passes";
}

void unmap(void* block, std::size_t bytes) {
  ::munmap(block, bytes);
}

// The mapped image of `path` when it is one of width x height x kChannelCount, else nullopt.
std::optional<Image<float>> map_passes(const std::string& path, int width, int height) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  struct stat st {};
  FileHeader h{};
  const bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
                  ::pread(fd, &h, sizeof h, 0) == ssize_t(sizeof h) &&
                  std::memcmp(h.magic, kMagic, sizeof kMagic) == 0 && h.width == width &&
                  h.height == height && h.channels == render::kChannelCount &&
                  h.stride >= int64_t(width) * h.channels &&
                  h.stride % int64_t(kRowAlign / sizeof(float)) == 0 &&
                  uint64_t(st.st_size) == sizeof h + uint64_t(h.stride) * uint64_t(height) * 4;
  void* block =
      ok ? ::mmap(nullptr, std::size_t(st.st_size), PROT_READ | PROT_WRITE, MAP_PRIVATE, fd, 0)
         : MAP_FAILED;
  ::close(fd);
  if (block == MAP_FAILED) return std::nullopt;
  float* data = reinterpret_cast<float*>(static_cast<char*>(block) + sizeof h);
  return Image<float>::adopt(data, width, height, h.channels, std::ptrdiff_t(h.stride), block,
                             std::size_t(st.st_size), unmap);
}

}  // namespace

std::string reference_key(const pipeline::Exemplar& exemplar, int width, int height) {
  // FNV-1a over the manifest's lines.
  uint64_t h = kFnvOffset;
  for (const std::string& line : reference_manifest(exemplar, width, height))
    h = fnv1a(line + "\n", h);
  return fmt::format("{:016x}", h);
}

std::optional<Image<float>> read_reference(const std::string& output_folder, const std::string& key,
                                           int width, int height) {
  const std::string dir = folder_of(output_folder);
  const std::optional<std::string> want =
      read_input_file(dir + "/" + key + ".digest", 64);  // "16 hex digits\n"
  if (!want) return std::nullopt;
  std::optional<Image<float>> passes = map_passes(pixels_path(dir, key), width, height);
  if (!passes || digest_text(passes->cview()) != *want) return std::nullopt;
  return passes;
}

void write_reference(const std::string& output_folder, const std::string& key,
                     ImageView<const float> passes) {
  CHECK_EQ(passes.channels, render::kChannelCount);
  const std::string dir = folder_of(output_folder);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec))
    throw Error(dir, "cannot create the folder of the exemplars' reference passes");
  // The pixels first, their digest last: a digest file names only a finished image.
  const std::string digest = dir + "/" + key + ".digest";
  fs::remove(digest, ec);
  const std::string path = pixels_path(dir, key);
  const std::size_t row = std::size_t(passes.width) * std::size_t(passes.channels);
  const std::size_t stride = (row * sizeof(float) + kRowAlign - 1) / kRowAlign * kRowAlign / 4;
  FileHeader h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.width = passes.width, h.height = passes.height, h.channels = passes.channels;
  h.stride = int64_t(stride);
  TempFile pixels(path, path);
  pixels.write(&h, sizeof h);
  std::vector<float> padded(stride, 0.f);
  for (int y = 0; y < passes.height; ++y) {
    std::memcpy(padded.data(), passes.row(y), row * sizeof(float));
    pixels.write(padded.data(), stride * sizeof(float));
  }
  pixels.commit();
  const std::string text = digest_text(passes);
  TempFile tmp(digest, digest);
  tmp.write(text.data(), text.size());
  tmp.commit();
}

}  // namespace emaki::io
