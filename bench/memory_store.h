// A pipeline::Store that keeps layer frames in memory and drops composited frames, so a
// benchmark times rendering + synthesis + advection + compositing without file output.
#pragma once

#include <cstring>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/run.h"

namespace emaki::bench {

class MemoryStore : public pipeline::Store {
 public:
  bool has_layer(const pipeline::Layer& l, int f) const override {
    return layers_.count({l.name, f}) > 0;
  }
  Image<float> read_layer(const pipeline::Layer& l, int f) const override {
    return layers_.at({l.name, f}).clone();
  }
  void write_layer(const pipeline::Layer& l, int f, ImageView<const float> v) override {
    Image<float> img(v.width, v.height, v.channels);
    for (int y = 0; y < v.height; ++y)
      std::memcpy(img.row(y), v.row(y), sizeof(float) * v.width * v.channels);
    layers_[{l.name, f}] = std::move(img);
  }
  bool has_frame(int) const override { return false; }
  void write_frame(int, ImageView<const float>, const std::vector<ImageView<const float>>&,
                   ImageView<const float>) override {}

 private:
  std::map<std::pair<std::string, int>, Image<float>> layers_;
};

}  // namespace emaki::bench
