#include "pipeline/ink_ratio.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "pipeline/frames.h"
#include "render/passes.h"

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

// The object a pixel shows (render::kObjectId; 0, the background, where the passes have none).
int object_at(ImageView<const float> passes, int x, int y) {
  if (passes.channels <= render::kObjectId) return 0;
  const float* p = passes.at(x, y);
  return p[render::kAlpha] > 0.5f ? int(std::lround(p[render::kObjectId])) : 0;
}

bool by_object(const TemporalSpec& t) {
  return t.ink_objects && t.ink_guide.empty() && t.ink_bins <= 0;
}

// The mean ink per covered pixel of each object covering at least ink_object_pixels().
std::vector<std::pair<int, double>> object_inks(ImageView<const float> v, int n,
                                                ImageView<const float> passes) {
  std::map<int, std::pair<double, long>> sums;
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x)
      if (covered(v, n, x, y)) {
        auto& [ink, count] = sums[object_at(passes, x, y)];
        ink += ink_at(v, n, x, y), ++count;
      }
  std::vector<std::pair<int, double>> out;
  const long fewest = ink_object_pixels(v.width, v.height);
  for (const auto& [id, s] : sums)
    if (s.second >= fewest && s.first > kFloor * double(s.second))
      out.emplace_back(id, s.first / double(s.second));
  return out;
}

// pin_ink_ratio with t.ink_objects. Each object `ref` measured gets a factor to its own mean
// ink, in full once it covers 4 x ink_object_pixels() of the frame and in proportion below that
// (an object growing or shrinking through the threshold does not jump); the rest of its move,
// and every other covered pixel's, is the factor of the pixels of the objects `ref` did not
// measure to the layer's mean ink, or of all the covered pixels when those are too few.
void pin_by_object(const TemporalSpec& t, int n, ImageView<const float> passes,
                   const InkReference& ref, Image<float>& value, const Trust& trust) {
  struct Sums {
    double layer = 0.0, trusted = 0.0;
    long pixels = 0;
    void add(double ink, float trust) { layer += ink, trusted += trust * ink, ++pixels; }
  };
  auto share_of = [&](const Sums& g, double expected) {
    const double m = double(std::max(1L, g.pixels));
    const double layer = g.layer / m, trusted = g.trusted / m;
    if (layer <= kFloor || expected <= kFloor || trusted <= kFloor) return 0.0f;
    return float(t.ink_ratio * (std::clamp(1.0 + (expected - layer) / trusted, 0.5, 2.0) - 1.0));
  };
  // Each pixel's group: the index of its object in ref.per_object, or -1 (the rest). Looked up
  // once per run of pixels of one object, not per pixel.
  std::map<int, int> index;
  for (std::size_t k = 0; k < ref.per_object.size(); ++k) index[ref.per_object[k].first] = int(k);
  int last_id = -1, last_group = -1;
  auto group_at = [&](int x, int y) {
    const int id = object_at(passes, x, y);
    if (id != last_id) {
      const auto it = index.find(id);
      last_id = id, last_group = it == index.end() ? -1 : it->second;
    }
    return last_group;
  };
  std::vector<Sums> objects(ref.per_object.size());
  Sums rest, all;
  const ImageView<const float> v = value.cview();
  for (int y = 0; y < v.height; ++y)
    for (int x = 0; x < v.width; ++x) {
      if (!covered(v, n, x, y)) continue;
      const int g = group_at(x, y);
      const double ink = ink_at(v, n, x, y);
      const float tr = trust.at(x, y);
      all.add(ink, tr);
      (g >= 0 ? objects[std::size_t(g)] : rest).add(ink, tr);
    }
  const long fewest = ink_object_pixels(v.width, v.height);
  const float base = share_of(rest.pixels >= fewest ? rest : all, ref.per_bin[0]);
  std::vector<float> share(objects.size());
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const float full = std::min(1.0f, float(objects[k].pixels) / float(4 * fewest));
    share[k] = base + full * (share_of(objects[k], ref.per_object[k].second) - base);
  }
  for (int y = 0; y < value.height(); ++y)
    for (int x = 0; x < value.width(); ++x) {
      if (!covered(value.cview(), n, x, y)) continue;
      const int g = group_at(x, y);
      const float scale = 1.0f + trust.at(x, y) * (g >= 0 ? share[std::size_t(g)] : base);
      for (int c = 0; c < n; ++c)
        value(x, y, c) = std::clamp(1.0f - scale * (1.0f - value(x, y, c)), 0.0f, 1.0f);
    }
}

}  // namespace

long ink_object_pixels(int width, int height) {
  return std::max(32L, long(width) * long(height) / 1000);
}

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
    if (by_object(t) && !ref.per_bin.empty()) ref.per_object = object_inks(value, n, passes);
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

int ink_next_reference_frame(const TemporalSpec& t, int first, int last, int f) {
  if (!t.ink_blend || t.ink_refresh <= 0) return -1;
  const int next = ink_reference_frame(t, first, f) + t.ink_refresh;
  return next <= last ? next : -1;
}

InkReference blend_ink_references(const InkReference& a, const InkReference& b, double s) {
  auto mix = [s](double x, double y) { return x + s * (y - x); };
  InkReference out;
  if (a.per_bin.size() == b.per_bin.size()) {
    out.per_bin.resize(a.per_bin.size());
    for (std::size_t k = 0; k < a.per_bin.size(); ++k)
      out.per_bin[k] = mix(a.per_bin[k], b.per_bin[k]);
  } else {
    out.per_bin = a.per_bin.empty() ? b.per_bin : a.per_bin;
  }
  std::map<int, double> objects;  // b's, then a's blended into them or added
  for (const auto& [id, ink] : b.per_object) objects[id] = ink;
  for (const auto& [id, ink] : a.per_object) {
    const auto it = objects.find(id);
    objects[id] = it == objects.end() ? ink : mix(ink, it->second);
  }
  out.per_object.assign(objects.begin(), objects.end());
  return out;
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
  if (by_object(t)) {
    pin_by_object(t, value_channels, passes, ref, value, trust);
    return;
  }
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

void InkPin::pin(const TemporalSpec& t, int first, int last, int f, bool chained,
                 int value_channels, ImageView<const float> passes, Image<float>& value,
                 const Image<float>& confidence, const Measure& measure) {
  if (chained && t.ink_refresh > 0) refresh(t, first, last, f, measure);
  pin_ink_ratio(t, value_channels, passes, chained, ref_, value, confidence);
  if (!chained) {  // a fresh transfer: what a refresh at this frame measures
    ref_.frame = f;
    kept_ = {ref_, InkReference{}};
  }
}

void InkPin::refresh(const TemporalSpec& t, int first, int last, int f, const Measure& measure) {
  const int r = ink_reference_frame(t, first, f);
  if (!t.ink_blend) {
    if (ref_.frame != r) ref_ = measure(r);
    return;
  }
  const int next = ink_next_reference_frame(t, first, last, f);
  for (const int k : {r, next})
    if (k >= 0 && kept_[0].frame != k && kept_[1].frame != k)
      kept_[kept_[0].frame == r ? 1 : 0] = measure(k);
  const InkReference& at = kept_[kept_[0].frame == r ? 0 : 1];
  if (next < 0) {
    ref_ = at;
    return;
  }
  ref_ = blend_ink_references(at, kept_[kept_[0].frame == next ? 0 : 1],
                              double(f - r) / double(next - r));
  ref_.frame = f;
}

}  // namespace emaki::pipeline
