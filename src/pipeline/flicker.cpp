#include "pipeline/flicker.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/error.h"
#include "core/shot_keys.h"
#include "pipeline/qa_maps.h"
#include "render/passes.h"

namespace emaki::pipeline {

FrameFlicker frame_flicker(ImageView<const float> cur, ImageView<const float> prev,
                           ImageView<const float> cp, ImageView<const float> pp, int mask_channel,
                           Image<float>* map, const Image<uint8_t>* select) {
  CHECK_EQ(cur.width, prev.width);
  CHECK_EQ(cur.height, prev.height);
  CHECK_EQ(cp.width, cur.width);
  CHECK_EQ(pp.width, cur.width);
  if (select) CHECK_EQ(select->width(), cur.width);
  FrameFlicker out;
  const int w = cur.width, h = cur.height;
  if (map) *map = empty_qa_map(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* p = cp.at(x, y);
      if (p[render::kAlpha] < 1.0f || p[render::kOutline] > 0.0f) continue;
      if (mask_channel >= 0 && cur(x, y, mask_channel) < 1.0f) continue;
      if (select && !(*select)(x, y)) continue;
      const float id = p[render::kObjectId];
      if (id < 1.0f) continue;
      const float sx = x + p[render::kMotion], sy = y + p[render::kMotion + 1];
      const int x0 = int(std::floor(sx)), y0 = int(std::floor(sy));
      if (x0 < 0 || y0 < 0 || x0 + 1 >= w || y0 + 1 >= h) continue;
      const float fx = sx - x0, fy = sy - y0;
      bool ok = true;
      double v = 0.0;
      for (int j = 0; j < 2 && ok; ++j)
        for (int i = 0; i < 2 && ok; ++i) {
          const float* q = pp.at(x0 + i, y0 + j);
          if (q[render::kAlpha] < 1.0f || q[render::kObjectId] != id || q[render::kOutline] > 0.0f)
            ok = false;
          if (mask_channel >= 0 && prev(x0 + i, y0 + j, mask_channel) < 1.0f) ok = false;
          v += (i ? fx : 1 - fx) * (j ? fy : 1 - fy) * prev(x0 + i, y0 + j, 0);
        }
      if (!ok) continue;
      const double e = std::abs(double(cur(x, y, 0)) - v);
      if (map) {
        (*map)(x, y, 0) = float(std::min(1.0, e / kFlickerMapScale));
        (*map)(x, y, 1) = 1.0f;
      }
      out.all.sum += e, ++out.all.pixels;
      FlickerStats& s = id >= 2.0f ? out.objects : out.ground;
      s.sum += e, ++s.pixels;
      FlickerStats& o = out.by_id[int(std::lround(id))];
      o.sum += e, ++o.pixels;
    }
  return out;
}

SequenceFlicker measure_flicker(const Layer& layer, const FrameSource& frames, const Store& store,
                                int first, int last,
                                const std::function<void(const FrameFlicker&)>& each,
                                const std::function<void(int, const Image<float>&)>& maps) {
  CHECK_LT(first, last);
  for (int f = first; f <= last; ++f)
    if (!store.has_layer(layer, f))
      throw Error(shot_keys::layer(layer.name), fmt::format("frame {} is not synthesized yet", f));
  const int value_channels = layer.single_colour ? 1 : 3;
  SequenceFlicker mean;
  Image<float> prev = store.read_layer(layer, first), prev_passes = frames.passes(first);
  for (int f = first + 1; f <= last; ++f) {
    Image<float> cur = store.read_layer(layer, f), cur_passes = frames.passes(f);
    const int mask_channel = cur.channels() > value_channels ? value_channels : -1;
    Image<float> map;
    FrameFlicker ff = frame_flicker(cur.cview(), prev.cview(), cur_passes.cview(),
                                    prev_passes.cview(), mask_channel, maps ? &map : nullptr);
    ff.frame = f;
    if (each) each(ff);
    if (maps) maps(f, map);
    mean.add(ff);
    prev = std::move(cur);
    prev_passes = std::move(cur_passes);
  }
  return mean;
}

}  // namespace emaki::pipeline
