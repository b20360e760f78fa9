// The contact sheet: every frame as a box-filtered thumbnail on a grid (pipeline/run.h).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/check.h"
#include "pipeline/run.h"

namespace emaki::pipeline {

Image<float> contact_sheet(const std::vector<Image<float>>& frames, int columns, int thumb_width) {
  CHECK(!frames.empty());
  CHECK_GT(columns, 0);
  const int fw = frames[0].width(), fh = frames[0].height();
  const int tw = std::min(thumb_width, fw);
  const int th = std::max(1, int(std::lround(double(fh) * tw / fw)));
  const int gap = 4;
  const int rows = (int(frames.size()) + columns - 1) / columns;
  const int cols = std::min<int>(columns, int(frames.size()));
  Image<float> sheet(cols * tw + (cols + 1) * gap, rows * th + (rows + 1) * gap, 3);
  sheet.fill(1.0f);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    // Each thumbnail samples its own frame's size and channels: frames read back from disk need
    // not all match the first one, and a mismatch must never index past a frame.
    const Image<float>& f = frames[i];
    if (f.empty()) continue;
    const int sw = f.width(), sh = f.height(), last_channel = f.channels() - 1;
    const int ox = gap + int(i % columns) * (tw + gap), oy = gap + int(i / columns) * (th + gap);
    // Box filter over the source pixels each thumbnail pixel covers.
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x) {
        const int x0 = int(int64_t(x) * sw / tw),
                  x1 = std::max(x0 + 1, int(int64_t(x + 1) * sw / tw));
        const int y0 = int(int64_t(y) * sh / th),
                  y1 = std::max(y0 + 1, int(int64_t(y + 1) * sh / th));
        for (int c = 0; c < 3; ++c) {
          double s = 0;
          for (int yy = y0; yy < y1; ++yy)
            for (int xx = x0; xx < x1; ++xx) s += f(xx, yy, std::min(c, last_channel));
          sheet(ox + x, oy + y, c) = float(s / ((x1 - x0) * (y1 - y0)));
        }
      }
  }
  return sheet;
}

}  // namespace emaki::pipeline
