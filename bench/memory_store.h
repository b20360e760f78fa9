// A pipeline::Store that keeps layer frames in memory and drops composited frames, so a
// benchmark times rendering + synthesis + advection + compositing without file output. With
// `digest` set it folds every layer frame and composited frame it is given into one digest, so
// two builds can be checked for the same results (bit for bit) on the benchmark's own run.
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
  explicit MemoryStore(bool digest = false) : digesting_(digest) {}
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
    if (digesting_) add(pipeline::value_digest(v));
  }
  bool has_frame(int) const override { return false; }
  void write_frame(int, ImageView<const float> composite,
                   const std::vector<ImageView<const float>>&, ImageView<const float>) override {
    if (digesting_) add(pipeline::value_digest(composite));
  }
  // Of everything written so far, in the order it was written.
  uint64_t digest() const { return digest_; }

 private:
  void add(uint64_t h) { digest_ = (digest_ ^ h) * 0x100000001b3ull; }
  bool digesting_ = false;
  uint64_t digest_ = 0xcbf29ce484222325ull;
  std::map<std::pair<std::string, int>, Image<float>> layers_;
};

}  // namespace emaki::bench
