// Small paintings for the shot tests: box-filtered copies of a bundled painting (by default a
// 100x76 copy of the StyLit painting, used as a MatCap-like exemplar), so exemplar pyramids and
// the reference sphere's renders stay tiny and the tests stay fast, under the sanitizers too.
#pragma once

#include <string>

#include "core/image.h"
#include "io/image_io.h"

namespace emaki::test {

// Writes `png` box-filtered to w x h (every channel it has) as an 8-bit image at `out`.
inline void write_small_painting(const std::string& png, const std::string& out, int w = 100,
                                 int h = 76) {
  const Image<float> big = io::read_image_float(png);
  const int nc = big.channels();
  Image<float> small(w, h, nc);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < nc; ++c) {
        const int x0 = x * big.width() / w, x1 = (x + 1) * big.width() / w;
        const int y0 = y * big.height() / h, y1 = (y + 1) * big.height() / h;
        double s = 0;
        for (int yy = y0; yy < y1; ++yy)
          for (int xx = x0; xx < x1; ++xx) s += big(xx, yy, c);
        small(x, y, c) = float(s / ((x1 - x0) * (y1 - y0)));
      }
  io::WriteOptions wo;
  wo.format = io::SampleFormat::kU8;
  io::write_image(out, small.cview(), wo);
}

}  // namespace emaki::test
