// The small painting the shot tests use as a MatCap-like exemplar: a 100x76 box-filtered copy of
// the StyLit painting, so exemplar pyramids stay tiny and tests stay fast.
#pragma once

#include <string>

#include "core/image.h"
#include "io/image_io.h"

namespace emaki::test {

inline void write_small_painting(const std::string& stylit_png, const std::string& out) {
  const Image<float> big = io::read_image_float(stylit_png);
  const int w = 100, h = 76;
  Image<float> small(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
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
