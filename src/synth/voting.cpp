#include "synth/voting.h"

#include <type_traits>
#include <vector>

#include "core/parallel.h"

namespace emaki::synth {

namespace {
template <typename T>
inline float norm(T v) {
  if constexpr (std::is_same_v<T, uint8_t>) return float(v) * (1.0f / 255.0f);
  else if constexpr (std::is_same_v<T, uint16_t>) return float(v) * (1.0f / 65535.0f);
  else return float(v);
}

template <typename T>
void vote_impl(ImageView<const T> source, const Image<int32_t>& nnf, const Image<float>& err,
               const Image<uint8_t>& active, int patch_size, VoteMode mode, Image<float>& out) {
  const int tw = nnf.width(), th = nnf.height(), nc = source.channels;
  const int r = patch_size / 2;
  if (out.width() != tw || out.height() != th || out.channels() != nc) out.reset(tw, th, nc);
  const bool all = active.empty();
  // EbSynth's weighting: error per patch pixel and channel.
  const float err_norm = 1.0f / float(patch_size * patch_size * nc);
  parallel_rows(th, 16, [&](int y0, int y1) {
    // Double sums: where every patch agrees the vote returns exactly the source value, so an
    // exact match stays exact after re-quantisation.
    std::vector<double> acc(nc);
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < tw; ++x) {
        float* o = out.at(x, y);
        if (!all && !active(x, y)) {
          for (int c = 0; c < nc; ++c) o[c] = 0.0f;
          continue;
        }
        std::fill(acc.begin(), acc.end(), 0.0);
        double wsum = 0.0;
        for (int oy = -r; oy <= r; ++oy) {
          const int uy = y + oy;
          if (uy < 0 || uy >= th) continue;
          for (int ox = -r; ox <= r; ++ox) {
            const int ux = x + ox;
            if (ux < 0 || ux >= tw || (!all && !active(ux, uy))) continue;
            const int32_t* m = nnf.at(ux, uy);
            const T* s = source.at(m[0] - ox, m[1] - oy);
            const float w = mode == VoteMode::kPlain ? 1.0f : 1.0f / (1.0f + err(ux, uy) * err_norm);
            for (int c = 0; c < nc; ++c) acc[c] += double(w) * norm(s[c]);
            wsum += w;
          }
        }
        // The pixel's own patch always counts: wsum > 0.
        for (int c = 0; c < nc; ++c) o[c] = float(acc[c] / wsum);
      }
  });
}

}  // namespace

void vote(const Plane& source, const Image<int32_t>& nnf, const Image<float>& err,
          const Image<uint8_t>& active, int patch_size, VoteMode mode, Image<float>& out) {
  std::visit([&](const auto& v) { vote_impl(v, nnf, err, active, patch_size, mode, out); }, source);
}

}  // namespace emaki::synth
