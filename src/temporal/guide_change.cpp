#include "temporal/guide_change.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/check.h"
#include "core/parallel.h"

namespace emaki::temporal {

Image<float> guide_change(const Image<int32_t>& nnf, ImageView<const float> previous,
                          ImageView<const float> current) {
  const int w = current.width, h = current.height, n = current.channels;
  CHECK_EQ(nnf.width(), w);
  CHECK_EQ(nnf.height(), h);
  CHECK_EQ(previous.channels, n);
  Image<float> out(w, h, 1);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        const int qx = nnf(x, y, 0), qy = nnf(x, y, 1);
        if (qx < 0 || qy < 0 || qx >= previous.width || qy >= previous.height) {
          out(x, y) = 1.0f;
          continue;
        }
        const float* p = current.at(x, y);
        const float* q = previous.at(qx, qy);
        float d = 0.0f;
        for (int c = 0; c < n; ++c) d = std::max(d, std::abs(p[c] - q[c]));
        out(x, y) = d;
      }
  });
  return out;
}

namespace {

std::vector<float> gaussian_kernel(float sigma) {
  const int r = std::max(1, int(std::ceil(3.0f * sigma)));
  std::vector<float> k(2 * r + 1);
  for (int i = -r; i <= r; ++i) k[i + r] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
  return k;
}

// One separable pass along x or y: value x weight and weight, both convolved. Each pixel's taps
// are added in kernel order in doubles, the columns' a whole row of pixels at a time.
void blur_pass(const Image<float>& in, const Image<float>& in_w, Image<float>& out,
               Image<float>& out_w, const std::vector<float>& k, bool along_x) {
  const int w = in.width(), h = in.height(), n = in.channels(), r = int(k.size()) / 2;
  out.reset(w, h, n);
  out_w.reset(w, h, 1);
  parallel_rows(h, 16, [&](int y0, int y1) {
    std::vector<double> acc(std::size_t(w) * n), sum(static_cast<std::size_t>(w));
    for (int y = y0; y < y1; ++y) {
      std::fill(acc.begin(), acc.end(), 0.0);
      std::fill(sum.begin(), sum.end(), 0.0);
      if (along_x) {
        const float* row = in.row(y);
        const float* row_w = in_w.row(y);
        for (int x = 0; x < w; ++x) {
          double* a = acc.data() + std::size_t(x) * n;
          double& sw = sum[std::size_t(x)];
          for (int i = -r; i <= r; ++i) {
            const int u = std::clamp(x + i, 0, w - 1);
            const double wt = double(k[i + r]) * row_w[u];
            sw += wt;
            for (int c = 0; c < n; ++c) a[c] += wt * row[std::size_t(u) * n + c];
          }
        }
      } else {
        for (int i = -r; i <= r; ++i) {
          const int v = std::clamp(y + i, 0, h - 1);
          const float* row = in.row(v);
          const float* row_w = in_w.row(v);
          const double kw = double(k[i + r]);
          for (int x = 0; x < w; ++x) {
            const double wt = kw * row_w[x];
            sum[std::size_t(x)] += wt;
            for (int c = 0; c < n; ++c)
              acc[std::size_t(x) * n + c] += wt * row[std::size_t(x) * n + c];
          }
        }
      }
      for (int x = 0; x < w; ++x) {
        const double sw = sum[std::size_t(x)];
        out_w(x, y) = float(sw);
        for (int c = 0; c < n; ++c)
          out(x, y, c) = sw > 0.0 ? float(acc[std::size_t(x) * n + c] / sw) : in(x, y, c);
      }
    }
  });
}

}  // namespace

Image<float> low_pass(ImageView<const float> image, float sigma, ImageView<const float> mask) {
  const int w = image.width, h = image.height, n = image.channels;
  Image<float> src(w, h, n), weight(w, h, 1);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        for (int c = 0; c < n; ++c) src(x, y, c) = image(x, y, c);
        weight(x, y) = mask.empty() || mask(x, y, 0) > 0.0f ? 1.0f : 0.0f;
      }
  });
  if (sigma <= 0.0f) return src;
  const std::vector<float> k = gaussian_kernel(sigma);
  Image<float> rows, rows_w, out, out_w;
  blur_pass(src, weight, rows, rows_w, k, true);
  // The column pass weighs each row result by how much of the mask it saw.
  blur_pass(rows, rows_w, out, out_w, k, false);
  if (!mask.empty())
    parallel_rows(h, 32, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x)
          if (weight(x, y) <= 0.0f)
            for (int c = 0; c < n; ++c) out(x, y, c) = src(x, y, c);
    });
  return out;
}

}  // namespace emaki::temporal
