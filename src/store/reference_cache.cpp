#include "store/reference_cache.h"

#include <fmt/format.h>

#include <filesystem>

#include "core/error.h"
#include "core/fnv.h"
#include "io/image_io.h"
#include "io/temp_file.h"
#include "pipeline/run.h"
#include "render/passes.h"
#include "store/output_store.h"
#include "store/settings_manifests.h"

namespace emaki::io {

namespace fs = std::filesystem;

namespace {

std::string folder_of(const std::string& output_folder) {
  return (fs::path(output_folder) / "references").string();
}

std::string digest_text(ImageView<const float> passes) {
  return fmt::format("{:016x}\n", pipeline::value_digest(passes));
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
  std::optional<AnyImage> read;
  try {
    // By name: an EXR keeps its channels sorted, not in the passes' order.
    read = read_image_if_complete(dir + "/" + key + ".exr", ReadOptions{render::channel_names()});
  } catch (const Error&) {
    return std::nullopt;
  }
  if (!read) return std::nullopt;
  Image<float> passes = std::move(*read).to_float();
  if (passes.width() != width || passes.height() != height ||
      passes.channels() != render::kChannelCount || digest_text(passes.cview()) != *want)
    return std::nullopt;
  return passes;
}

void write_reference(const std::string& output_folder, const std::string& key,
                     ImageView<const float> passes) {
  const std::string dir = folder_of(output_folder);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec))
    throw Error(dir, "cannot create the folder of the exemplars' reference passes");
  // The pixels first, their digest last: a digest file names only a finished image.
  const std::string digest = dir + "/" + key + ".digest";
  fs::remove(digest, ec);
  WriteOptions exr;
  exr.format = SampleFormat::kFloat;
  exr.channel_names = render::channel_names();
  exr.compression = kIntermediateCompression;
  write_image(dir + "/" + key + ".exr", passes, exr);
  const std::string text = digest_text(passes);
  TempFile tmp(digest, digest);
  tmp.write(text.data(), text.size());
  tmp.commit();
}

}  // namespace emaki::io
