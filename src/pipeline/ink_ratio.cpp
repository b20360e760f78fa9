#include "pipeline/ink_ratio.h"

#include <algorithm>
#include <cmath>

#include "pipeline/frames.h"

namespace emaki::pipeline {

namespace {

// Below this mean ink a layer or its guide counts as blank: no ratio is measured or pinned.
constexpr double kFloor = 1e-4;

// The layer's ink guide at a frame (1 where it has none), and the bin of each of its values.
struct InkGuide {
  Image<float> pass;
  bool inverse = false;
  int bins = 0;
  InkGuide(const TemporalSpec& t, ImageView<const float> passes) : bins(t.ink_bins) {
    inverse = t.ink_guide.rfind("1-", 0) == 0;
    const std::string name = inverse ? t.ink_guide.substr(2) : t.ink_guide;
    if (!name.empty()) pass = extract_pass(passes, name);
  }
  float at(int x, int y) const {
    const float g = pass.empty() ? 1.0f : std::clamp(pass(x, y, 0), 0.0f, 1.0f);
    return inverse ? 1.0f - g : g;
  }
  int bin(float g) const { return std::min(bins - 1, int(g * float(bins))); }
};

bool covered(ImageView<const float> v, int n, int x, int y) {
  return v.channels <= n || v(x, y, n) >= 0.5f;
}

double ink_at(ImageView<const float> v, int n, int x, int y) {
  double s = 0.0;
  for (int c = 0; c < n; ++c) s += 1.0 - v(x, y, c);
  return s / n;
}

// The layer's mean ink over its coverage, what the reference expects there (`ref`'s ratio times
// the guide's mean ink, or the mean of its per-bin inks at each pixel's bin), and the mean ink
// weighted by Trust, the share a per-pixel scaling moves.
struct Inks {
  double layer = 0.0, expected = 0.0, trusted = 0.0;
};

// How much of the frame's factor a pixel takes: 1 - w + w x its confidence (TemporalSpec::
// ink_confident w; no confidence: 1).
struct Trust {
  const Image<float>* confidence = nullptr;
  float weight = 0.0f;
  float at(int x, int y) const {
    if (!confidence) return 1.0f;
    return 1.0f - weight + weight * std::clamp((*confidence)(x, y), 0.0f, 1.0f);
  }
};

Inks inks(const InkGuide& g, ImageView<const float> v, int n, const InkReference& ref,
          const Trust& trust) {
  Inks s;
  long pixels = 0;
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) {
      if (!covered(v, n, x, y)) continue;
      ++pixels;
      const double ink = ink_at(v, n, x, y);
      s.layer += ink;
      s.trusted += trust.at(x, y) * ink;
      const float gi = g.at(x, y);
      s.expected += g.bins > 0 ? ref.per_bin[g.bin(gi)] : ref.per_bin[0] * gi;
    }
  if (pixels == 0) return {};
  const double m = double(pixels);
  return {s.layer / m, s.expected / m, s.trusted / m};
}

}  // namespace

InkReference ink_reference(const TemporalSpec& t, ImageView<const float> value, int n,
                           ImageView<const float> passes) {
  const InkGuide g(t, passes);
  const int bins = std::max(1, g.bins);
  std::vector<double> ink(bins, 0.0), guide(bins, 0.0);
  std::vector<long> count(bins, 0);
  for (int y = 0; y < value.height; ++y)
    for (int x = 0; x < value.width; ++x) {
      if (!covered(value, n, x, y)) continue;
      const float gi = g.at(x, y);
      const int b = g.bins > 0 ? g.bin(gi) : 0;
      ink[b] += ink_at(value, n, x, y), guide[b] += gi, ++count[b];
    }
  InkReference ref;
  if (g.bins <= 0) {  // the ratio of the means
    if (ink[0] > kFloor * double(count[0]) && guide[0] > kFloor * double(count[0]))
      ref.per_bin = {ink[0] / guide[0]};
    return ref;
  }
  // Each bin's mean ink; a bin without pixels takes its nearest bin's that has some.
  ref.per_bin.assign(bins, -1.0);
  for (int b = 0; b < bins; ++b)
    if (count[b] > 0) ref.per_bin[b] = ink[b] / double(count[b]);
  for (int b = 0; b < bins; ++b)
    for (int d = 1; ref.per_bin[b] < 0.0 && d < bins; ++d)
      for (int k : {b - d, b + d})
        if (k >= 0 && k < bins && count[k] > 0 && ref.per_bin[b] < 0.0)
          ref.per_bin[b] = ink[k] / double(count[k]);
  if (ref.per_bin[0] < 0.0) ref.per_bin.clear();  // no pixel at all
  return ref;
}

int ink_reference_frame(const TemporalSpec& t, int first, int f) {
  if (t.ink_refresh <= 0 || f <= first) return first;
  return first + (f - first) / t.ink_refresh * t.ink_refresh;
}

void pin_ink_ratio(const TemporalSpec& t, int value_channels, ImageView<const float> passes,
                   bool chained, InkReference& ref, Image<float>& value,
                   const Image<float>& confidence) {
  if (!chained || ref.per_bin.empty()) {
    ref = ink_reference(t, value.cview(), value_channels, passes);
    return;
  }
  const Trust trust{t.ink_confident > 0.0f && !confidence.empty() ? &confidence : nullptr,
                    std::clamp(t.ink_confident, 0.0f, 1.0f)};
  const Inks s = inks(InkGuide(t, passes), value.cview(), value_channels, ref, trust);
  // s.trusted, the ink the factor moves, is its lever.
  if (s.layer <= kFloor || s.expected <= kFloor || s.trusted <= kFloor) return;
  const int n = value_channels;
  const double k = std::clamp(1.0 + (s.expected - s.layer) / s.trusted, 0.5, 2.0);
  const float share = float(t.ink_ratio * (k - 1.0));
  for (int y = 0; y < value.height(); ++y)
    for (int x = 0; x < value.width(); ++x) {
      if (!covered(value.cview(), n, x, y)) continue;
      const float scale = 1.0f + trust.at(x, y) * share;
      for (int c = 0; c < n; ++c)
        value(x, y, c) = std::clamp(1.0f - scale * (1.0f - value(x, y, c)), 0.0f, 1.0f);
    }
}

}  // namespace emaki::pipeline
