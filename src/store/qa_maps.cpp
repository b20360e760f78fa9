#include "store/qa_maps.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "core/check.h"
#include "core/error.h"
#include "io/image_io.h"

namespace emaki::io {

std::string qa_map_png(const std::string& output_folder, const std::string& kind,
                       const std::string& layer, int frame) {
  return fmt::format("{}/qa/{}/{}/frame_{:04d}.png", output_folder, kind, layer, frame);
}

Image<float> qa_map_colours(ImageView<const float> map) {
  CHECK_EQ(map.channels, 2);
  Image<float> rgb(map.width, map.height, 3);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      if (map(x, y, 1) <= 0.0f) continue;
      const float v = std::clamp(map(x, y, 0), 0.0f, 1.0f);
      // Dark blue at 0, red at 1/3, yellow at 2/3, white at 1: brighter is worse.
      rgb(x, y, 0) = std::min(1.0f, 3.0f * v);
      rgb(x, y, 1) = std::clamp(3.0f * v - 1.0f, 0.0f, 1.0f);
      rgb(x, y, 2) = std::max(0.3f * (1.0f - 3.0f * v), std::clamp(3.0f * v - 2.0f, 0.0f, 1.0f));
    }
  return rgb;
}

std::string write_qa_map(const std::string& output_folder, const std::string& kind,
                         const std::string& layer, int frame, ImageView<const float> map) {
  const std::string path = qa_map_png(output_folder, kind, layer, frame);
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (!std::filesystem::is_directory(folder, ec))
    throw Error(folder.string(), "cannot create the folder");
  WriteOptions png;
  png.format = SampleFormat::kU8;
  write_image(path, qa_map_colours(map).cview(), png);
  return path;
}

}  // namespace emaki::io
