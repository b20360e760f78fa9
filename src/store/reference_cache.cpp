#include "store/reference_cache.h"

#include <fmt/format.h>

#include <filesystem>
#include <optional>

#include "core/error.h"
#include "core/fnv.h"
#include "render/passes.h"
#include "store/mapped_passes.h"
#include "store/settings_manifests.h"

namespace emaki::io {

namespace fs = std::filesystem;

namespace {

std::string folder_of(const std::string& output_folder) {
  return (fs::path(output_folder) / "references").string();
}

std::string pixels_path(const std::string& dir, const std::string& key) {
  return dir + "/" + key + ".passes";
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
  return map_passes(pixels_path(folder_of(output_folder), key), width, height);
}

void write_reference(const std::string& output_folder, const std::string& key,
                     ImageView<const float> passes) {
  CHECK_EQ(passes.channels, render::kChannelCount);
  const std::string dir = folder_of(output_folder);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec))
    throw Error(dir, "cannot create the folder of the exemplars' reference passes");
  // Written whole under another name and renamed (io/temp_file.h): the file is there only
  // finished. The digest file earlier versions wrote beside it is not read any more.
  fs::remove(dir + "/" + key + ".digest", ec);
  write_mapped_passes(pixels_path(dir, key), passes);
}

}  // namespace emaki::io
