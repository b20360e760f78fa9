// The synthesizer's input planes (synthesizer.h's Plane: an 8-bit, 16-bit or float image) read
// as normalised floats (core/image.h's normalised()), and the checks and ranges the synthesizer
// takes from them. Internal to the synth module.
#pragma once

#include <cstddef>
#include <string>
#include <variant>
#include <vector>

#include "core/image.h"
#include "synth/synthesizer.h"

namespace emaki::synth {

inline bool is_float(const Plane& p) {
  return p.index() == 2;
}

// Calls fn(y, const float* values) per row of rows [y0, y1), the values normalised. Float rows
// are handed over in place (normalised() leaves floats as they are): copying them was a second
// pass over every guide, once per channel in plane_ranges.
template <typename Fn>
void for_each_row(const Plane& plane, int y0, int y1, Fn&& fn) {
  if (const auto* f = std::get_if<ImageView<const float>>(&plane)) {
    for (int y = y0; y < y1; ++y) fn(y, f->row(y));
    return;
  }
  std::visit(
      [&](const auto& v) {
        std::vector<float> row(std::size_t(v.width) * v.channels);
        for (int y = y0; y < y1; ++y) {
          const auto* s = v.row(y);
          for (std::size_t i = 0; i < row.size(); ++i) row[i] = normalised(s[i]);
          fn(y, row.data());
        }
      },
      plane);
}

// Widens each channel's [lo[c], hi[c]] (one entry per channel, 1 to 4) to the plane's values, in
// one pass. Min and max are exact and order-free, so bands may combine in any order.
void plane_ranges(const Plane& p, std::vector<float>& lo, std::vector<float>& hi);

// A float plane's first non-finite value (NaN or Inf) is an Error naming `name` and the pixel.
void check_finite(const Plane& p, const std::string& name);

// A guide pair's weight; a negative weight shares 1 equally among the `count` pairs.
float guide_weight(const GuidePair& g, std::size_t count);

}  // namespace emaki::synth
