#include "synth/weight_maps.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "core/error.h"
#include "core/parallel.h"
#include "synth/patch_distance.h"

namespace emaki::synth {

namespace {

// Calls fn(x, y, value) for the first channel of every pixel of rows [y0, y1), row by row.
template <typename Fn>
void for_each_value(const Plane& plane, int y0, int y1, Fn&& fn) {
  std::visit(
      [&](const auto& v) {
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < v.width; ++x) fn(x, y, normalised(v.at(x, y)[0]));
      },
      plane);
}

}  // namespace

void check_unit_map(const Plane& m, const std::string& name, int tw, int th) {
  if (plane_width(m) != tw || plane_height(m) != th)
    throw Error(name, fmt::format("map is {}x{} but the target is {}x{}", plane_width(m),
                                  plane_height(m), tw, th));
  // Bands look for a bad value at once; the first in row order is then named.
  std::atomic<bool> bad{false};
  parallel_rows(th, 32, [&](int y0, int y1) {
    for_each_value(m, y0, y1, [&](int, int, float v) {
      if (!(v >= 0.0f && v <= 1.0f)) bad.store(true, std::memory_order_relaxed);
    });
  });
  if (!bad) return;
  for_each_value(m, 0, th, [&](int x, int y, float v) {
    if (!(v >= 0.0f && v <= 1.0f))
      throw Error(name, fmt::format("map value {} at pixel ({}, {}) is not in [0, 1]", v, x, y));
  });
}

void check_weight_maps(const Inputs& in, const Params& p, int tw, int th) {
  int maps = 0, channels = plane_channels(in.style);
  for (const GuidePair& g : in.guides) {
    channels += plane_channels(g.source);
    if (!g.weight_map) continue;
    check_unit_map(*g.weight_map, g.weight_map_name.empty() ? g.name : g.weight_map_name, tw, th);
    ++maps;
  }
  if (maps == 0) return;
  if (maps > kMaxWeightMaps)
    throw Error("guides", fmt::format("at most {} guides may have a weight map (got {})",
                                      kMaxWeightMaps, maps));
  // A group's weighted sum is at most p^2 x channels x 16383^2 x 2^16: below 2^63 while
  // p^2 x channels <= 2^19, channels counted as the kernels read them (padded to an even count).
  const int padded = padded_channels(channels);
  if (int64_t(p.patch_size) * p.patch_size * padded > (int64_t(1) << 19))
    throw Error("patch size",
                fmt::format("{}x{} patches over {} channels are too large with weight maps "
                            "(patch area x channels must be <= 2^19)",
                            p.patch_size, p.patch_size, padded));
}

void assign_channel_groups(const Inputs& in, int patch_size, FeatureLayout& L) {
  L.group_of.assign(L.channels, 0);
  L.groups = 1;
  int c = L.style_channels;
  for (const GuidePair& g : in.guides) {
    const int nc = plane_channels(g.source);
    if (g.weight_map) {
      ++L.groups;
      for (int k = 0; k < nc; ++k) L.group_of[c + k] = L.groups - 1;
    }
    c += nc;
  }
  L.group_masks.clear();
  if (L.groups == 1) return;
  L.err_scale /= double(kGroupWeightOne);
  const int row_elems = patch_size * L.channels;
  L.group_masks.assign(std::size_t(L.groups) * row_elems, 0);
  for (int g = 0; g < L.groups; ++g)
    for (int i = 0; i < row_elems; ++i)
      if (L.group_of[i % L.channels] == g) L.group_masks[std::size_t(g) * row_elems + i] = -1;
}

Image<float> gather_map(const Plane& map, int tw, int th) {
  Image<float> out(tw, th, 1);
  parallel_rows(th, 32, [&](int y0, int y1) {
    for_each_value(map, y0, y1, [&](int x, int y, float v) { out(x, y) = v; });
  });
  return out;
}

Image<float> gather_weight_maps(const Inputs& in, int tw, int th) {
  int maps = 0;
  for (const GuidePair& g : in.guides) maps += g.weight_map ? 1 : 0;
  Image<float> out(tw, th, maps);
  int k = 0;
  for (const GuidePair& g : in.guides) {
    if (!g.weight_map) continue;
    parallel_rows(th, 32, [&](int y0, int y1) {
      for_each_value(*g.weight_map, y0, y1, [&](int x, int y, float v) { out(x, y, k) = v; });
    });
    ++k;
  }
  return out;
}

Image<int64_t> quantize_group_weights(const Image<float>& maps) {
  const int groups = maps.channels() + 1;
  Image<int64_t> out(maps.width(), maps.height(), groups);
  parallel_rows(maps.height(), 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < maps.width(); ++x) {
        int64_t* w = out.at(x, y);
        w[0] = kGroupWeightOne;
        for (int g = 1; g < groups; ++g) {
          const double m = std::clamp(double(maps(x, y, g - 1)), 0.0, 1.0);
          w[g] = std::llround(m * double(kGroupWeightOne));
        }
      }
  });
  return out;
}

}  // namespace emaki::synth
