#include "pipeline/qa_maps.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace emaki::pipeline {

Image<float> empty_qa_map(int width, int height) {
  return Image<float>(width, height, 2);
}

Image<float> synthesis_error_map(ImageView<const float> error, ImageView<const float> value,
                                 int value_channels, int patch_size) {
  CHECK_EQ(error.width, value.width);
  CHECK_EQ(error.height, value.height);
  const bool masked = value.channels > value_channels;
  const double per_pixel = 255.0 * 255.0 * patch_size * patch_size;
  Image<float> map = empty_qa_map(value.width, value.height);
  for (int y = 0; y < value.height; ++y)
    for (int x = 0; x < value.width; ++x) {
      if (masked && value(x, y, value_channels) <= 0.0f) continue;
      const double rms = std::sqrt(std::max(0.0, double(error(x, y, 0))) / per_pixel);
      map(x, y, 0) = float(std::min(1.0, rms / kErrorMapScale));
      map(x, y, 1) = 1.0f;
    }
  return map;
}

}  // namespace emaki::pipeline
