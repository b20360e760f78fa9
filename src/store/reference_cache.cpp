#include "store/reference_cache.h"

#include <fmt/format.h>

#include <cstring>
#include <filesystem>
#include <optional>

#include "core/error.h"
#include "core/fnv.h"
#include "io/temp_file.h"
#include "render/passes.h"
#include "store/mapped_passes.h"
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
  FnvLanes lanes;
  const std::size_t row = std::size_t(passes.width) * std::size_t(passes.channels) * sizeof(float);
  for (int y = 0; y < passes.height; ++y) lanes.add(passes.row(y), row);
  uint64_t h = kFnvOffset;
  for (const int32_t v : {passes.width, passes.height, passes.channels})
    h = fnv1a_add(h, uint32_t(v));
  return lanes.value(h);
}

std::string digest_text(ImageView<const float> passes) {
  return fmt::format("{:016x}\n", pixels_digest(passes));
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
  write_mapped_passes(pixels_path(dir, key), passes);
  const std::string text = digest_text(passes);
  TempFile tmp(digest, digest);
  tmp.write(text.data(), text.size());
  tmp.commit();
}

}  // namespace emaki::io
