#include "synth/voting.h"

#include <algorithm>
#include <type_traits>
#include <vector>

#include "core/parallel.h"

namespace emaki::synth {

namespace {
constexpr float kVoteSoftness = 100.0f;

// Integer samples are summed as they are and scaled once at the end.
template <typename T>
constexpr double sample_scale() {
  if constexpr (std::is_same_v<T, uint8_t>)
    return 1.0 / 255.0;
  else if constexpr (std::is_same_v<T, uint16_t>)
    return 1.0 / 65535.0;
  else
    return 1.0;
}

// The per-pixel vote (patches other than 3x3 and 5x5); Plain: every patch weighs 1.
template <int NC, typename T, bool Plain>
void vote_rows(ImageView<const T> source, const Image<int32_t>& nnf, const Image<float>& weight,
               const Image<uint8_t>& active, int r, Image<float>& out, int y0, int y1) {
  const int tw = nnf.width(), th = nnf.height();
  const bool all = active.empty();
  constexpr double scale = sample_scale<T>();
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < tw; ++x) {
      float* o = out.at(x, y);
      if (!all && !active(x, y)) {
        for (int c = 0; c < NC; ++c) o[c] = 0.0f;
        continue;
      }
      // Double sums: where every patch agrees the vote returns exactly the source value, so an
      // exact match stays exact after re-quantisation.
      double acc[NC] = {};
      double wsum = 0.0;
      const int uy0 = std::max(0, y - r), uy1 = std::min(th - 1, y + r);
      const int ux0 = std::max(0, x - r), ux1 = std::min(tw - 1, x + r);
      for (int uy = uy0; uy <= uy1; ++uy) {
        const int32_t* m = nnf.at(ux0, uy);
        const float* wrow = Plain ? nullptr : weight.row(uy);
        for (int ux = ux0; ux <= ux1; ++ux, m += 2) {
          if (!all && !active(ux, uy)) continue;
          const T* s = source.at(m[0] - (ux - x), m[1] - (uy - y));
          const double w = Plain ? 1.0 : double(wrow[ux]);
          for (int c = 0; c < NC; ++c) acc[c] += w * double(s[c]);
          wsum += w;
        }
      }
      // The pixel's own patch always counts: wsum > 0.
      const double inv = scale / wsum;
      for (int c = 0; c < NC; ++c) o[c] = float(acc[c] * inv);
    }
}

// The same vote, row by row from the patches' side: output row y sums, for every active patch
// centred within r rows of it, that patch's source row — P contiguous pixels added to contiguous
// accumulators, which vectorizes, where the per-pixel form gathers P^2 scattered pixels. Each
// output pixel receives its patches in the per-pixel form's order (rows, then columns, upward),
// so the double sums are the same to the bit; plain integer sums are exact either way.
template <int NC, int P, typename T, bool Plain>
void vote_rows_scatter(ImageView<const T> source, const Image<int32_t>& nnf,
                       const Image<float>& weight, const Image<uint8_t>& active, Image<float>& out,
                       int y0, int y1) {
  constexpr int r = P / 2;
  const int tw = nnf.width(), th = nnf.height();
  const bool all = active.empty();
  constexpr double scale = sample_scale<T>();
  // int32 for plain integer samples: at most P^2 <= 25 samples of 16 bits per pixel.
  using Acc = std::conditional_t<Plain && std::is_integral_v<T>, int32_t, double>;
  // Offset by r pixels so that patches at the image's edges add whole rows; the columns outside
  // the image are dropped.
  std::vector<Acc> acc(std::size_t(tw + 2 * r) * NC), wsum(std::size_t(tw + 2 * r));
  for (int y = y0; y < y1; ++y) {
    std::fill(acc.begin(), acc.end(), Acc(0));
    std::fill(wsum.begin(), wsum.end(), Acc(0));
    for (int uy = std::max(0, y - r); uy <= std::min(th - 1, y + r); ++uy) {
      const int32_t* m = nnf.row(uy);
      for (int ux = 0; ux < tw; ++ux, m += 2) {
        if (!all && !active(ux, uy)) continue;
        const T* s = source.row(m[1] + (y - uy)) + std::ptrdiff_t(m[0] - r) * NC;
        Acc* a = acc.data() + std::size_t(ux) * NC;  // column ux - r
        Acc* ws = wsum.data() + ux;
        if constexpr (Plain) {
          for (int k = 0; k < P * NC; ++k) a[k] += Acc(s[k]);
          for (int k = 0; k < P; ++k) ws[k] += Acc(1);
        } else {
          const double w = weight(ux, uy);
          for (int k = 0; k < P * NC; ++k) a[k] += w * double(s[k]);
          for (int k = 0; k < P; ++k) ws[k] += w;
        }
      }
    }
    for (int x = 0; x < tw; ++x) {
      float* o = out.at(x, y);
      if (!all && !active(x, y)) {
        for (int c = 0; c < NC; ++c) o[c] = 0.0f;
        continue;
      }
      // The pixel's own patch always counts: wsum > 0.
      const double inv = scale / double(wsum[std::size_t(x) + r]);
      const Acc* a = acc.data() + (std::size_t(x) + r) * NC;
      for (int c = 0; c < NC; ++c) o[c] = float(double(a[c]) * inv);
    }
  }
}

template <int NC, typename T>
void vote_rows(ImageView<const T> source, const Image<int32_t>& nnf, const Image<float>& weight,
               const Image<uint8_t>& active, int r, Image<float>& out, int y0, int y1, bool plain) {
  if (source.channels == NC && (r == 1 || r == 2)) {  // 3x3 and 5x5 patches, packed pixels
    if (r == 2)
      return plain ? vote_rows_scatter<NC, 5, T, true>(source, nnf, weight, active, out, y0, y1)
                   : vote_rows_scatter<NC, 5, T, false>(source, nnf, weight, active, out, y0, y1);
    return plain ? vote_rows_scatter<NC, 3, T, true>(source, nnf, weight, active, out, y0, y1)
                 : vote_rows_scatter<NC, 3, T, false>(source, nnf, weight, active, out, y0, y1);
  }
  if (plain)
    vote_rows<NC, T, true>(source, nnf, weight, active, r, out, y0, y1);
  else
    vote_rows<NC, T, false>(source, nnf, weight, active, r, out, y0, y1);
}

template <typename T>
void vote_impl(ImageView<const T> source, const Image<int32_t>& nnf, const Image<float>& err,
               const Image<uint8_t>& active, int patch_size, VoteMode mode, Image<float>& out) {
  const int tw = nnf.width(), th = nnf.height(), nc = source.channels;
  const int r = patch_size / 2;
  if (out.width() != tw || out.height() != th || out.channels() != nc) out.reset(tw, th, nc);
  // Each patch's weight once, not once per pixel it covers: 1 / (1 + e / kVoteSoftness), e its
  // error per patch pixel and channel (EbSynth's units). With the softness, patches that agree
  // within about 10/255 RMS count nearly alike and only worse ones lose weight; at 1 (the former
  // 1 / (1 + e)) smooth exemplars came out as a patchwork of flat cells. Measured with
  // bench/eval_set.py (docs/design/engine-schedule.md): judge `style` on the MatCap pairs 1.2-2.5x
  // EbSynth's at 1, 1.05-2.1x at 100, while StyLit and FaceStyle stay under EbSynth's.
  const bool plain = mode == VoteMode::kPlain;
  Image<float> weight;
  if (!plain) weight.reset(tw, th, 1);
  const float err_norm = 1.0f / (float(patch_size * patch_size * nc) * kVoteSoftness);
  if (!plain)
    parallel_rows(th, 64, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < tw; ++x) weight(x, y) = 1.0f / (1.0f + err(x, y) * err_norm);
    });
  parallel_rows(th, 16, [&](int y0, int y1) {
    switch (nc) {
      case 1:
        vote_rows<1>(source, nnf, weight, active, r, out, y0, y1, plain);
        break;
      case 2:
        vote_rows<2>(source, nnf, weight, active, r, out, y0, y1, plain);
        break;
      case 3:
        vote_rows<3>(source, nnf, weight, active, r, out, y0, y1, plain);
        break;
      default:
        vote_rows<4>(source, nnf, weight, active, r, out, y0, y1, plain);
        break;
    }
  });
}

}  // namespace

void vote(const Plane& source, const Image<int32_t>& nnf, const Image<float>& err,
          const Image<uint8_t>& active, int patch_size, VoteMode mode, Image<float>& out) {
  std::visit([&](const auto& v) { vote_impl(v, nnf, err, active, patch_size, mode, out); }, source);
}

Image<uint8_t> dilate_mask(const Image<uint8_t>& inside, int radius) {
  const int w = inside.width(), h = inside.height(), r = radius;
  Image<uint8_t> across(w, h, 1), out(w, h, 1);
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t v = 0;
        for (int xx = std::max(0, x - r); xx <= std::min(w - 1, x + r) && !v; ++xx)
          v = inside(xx, y) ? 1 : 0;
        across(x, y) = v;
      }
  });
  parallel_rows(h, 32, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t v = 0;
        for (int yy = std::max(0, y - r); yy <= std::min(h - 1, y + r) && !v; ++yy)
          v = across(x, yy);
        out(x, y) = v;
      }
  });
  return out;
}

}  // namespace emaki::synth
