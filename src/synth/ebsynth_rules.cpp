// EbSynth's channel rules over images in memory (see ebsynth_rules.h).
#include "synth/ebsynth_rules.h"

#include <fmt/format.h>

#include <algorithm>
#include <type_traits>

#include "core/error.h"

namespace emaki::synth {
namespace {

template <typename T>
int effective_channels(const ImageView<const T>& v) {
  const int nc = v.channels, w = v.width, h = v.height;
  auto opaque = [&](int c) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (normalised(v(x, y, c)) != 1.0f) return false;
    return true;
  };
  auto gray = [&]() {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const T r = v(x, y, 0);
        if (v(x, y, 1) != r || v(x, y, 2) != r) return false;
      }
    return true;
  };
  if (nc == 4) return opaque(3) ? (gray() ? 1 : 3) : 4;
  if (nc == 3) return gray() ? 1 : 3;
  if (nc == 2) return opaque(1) ? 1 : 2;
  return nc;
}

}  // namespace

int effective_channels(const Plane& p) {
  return std::visit([](const auto& v) { return effective_channels(v); }, p);
}

Plane RuledInputs::with_channels(const Plane& p, int channels, bool is_guide) {
  const int have = plane_channels(p);
  if (have == channels) return p;
  return std::visit(
      [&](const auto& src) -> Plane {
        using T = std::remove_const_t<std::remove_reference_t<decltype(src(0, 0))>>;
        Image<T> o(src.width, src.height, channels);
        // Fewer channels keep the first ones; more spread a gray image (and its alpha) over RGB.
        const bool gray = have <= 2;
        for (int y = 0; y < src.height; ++y)
          for (int x = 0; x < src.width; ++x)
            for (int c = 0; c < channels; ++c) {
              int from = std::min(c, have - 1);
              if (gray) from = c < 3 ? 0 : have - 1;
              o(x, y, c) = src(x, y, from);
            }
        const ImageView<const T> view = o.cview();
        made_.push_back(std::move(o));
        made_for_guide_.push_back(is_guide);
        return view;
      },
      p);
}

void RuledInputs::release_guides() {
  inputs.guides.clear();
  std::vector<Made> kept;
  for (std::size_t i = 0; i < made_.size(); ++i)
    if (!made_for_guide_[i]) kept.push_back(std::move(made_[i]));
  made_ = std::move(kept);
  made_for_guide_.assign(made_.size(), false);
}

void check_guide_sizes(const NamedSize& style,
                       const std::vector<std::pair<NamedSize, NamedSize>>& guides) {
  for (const auto& [source, target] : guides)
    if (source.width != style.width || source.height != style.height)
      throw Error(source.name,
                  fmt::format("source guide is {}x{} but the style '{}' is {}x{}", source.width,
                              source.height, style.name, style.width, style.height));
  // Name the right image when sizes disagree.
  for (std::size_t k = 1; k < guides.size(); ++k) {
    const NamedSize &t = guides[k].second, &t0 = guides[0].second;
    if (t.width != t0.width || t.height != t0.height)
      throw Error(t.name, fmt::format("target guide is {}x{} but '{}' is {}x{}", t.width, t.height,
                                      t0.name, t0.width, t0.height));
  }
}

namespace {
NamedSize size_of(const NamedPlane& p) {
  return {p.name, plane_width(p.plane), plane_height(p.plane)};
}
}  // namespace

RuledInputs apply_ebsynth_rules(const NamedPlane& style, const std::vector<NamedGuide>& guides,
                                const std::optional<NamedPlane>& mask) {
  std::vector<std::pair<NamedSize, NamedSize>> sizes;
  for (const NamedGuide& g : guides) sizes.emplace_back(size_of(g.source), size_of(g.target));
  check_guide_sizes(size_of(style), sizes);
  RuledInputs r;
  Inputs& in = r.inputs;
  const int ns = effective_channels(style.plane);
  if (ns > 4) throw Error(style.name, "style must have 1 to 4 channels");
  in.style = r.with_channels(style.plane, ns, false);
  in.style_name = style.name;
  for (const NamedGuide& g : guides) {
    const int na = effective_channels(g.source.plane), nb = effective_channels(g.target.plane);
    const int nc = std::max(na, nb);
    // Named by the file that has too many, so the user knows which one to fix.
    if (nc > 4)
      throw Error(na > 4 ? g.source.name : g.target.name,
                  fmt::format("a guide must have 1 to 4 channels (has {})", nc));
    GuidePair gp;
    gp.name = g.target.name;
    gp.source_name = g.source.name;
    gp.source = r.with_channels(g.source.plane, nc, true);
    gp.target = r.with_channels(g.target.plane, nc, true);
    gp.weight = g.weight;
    in.guides.push_back(gp);
  }
  if (mask) {
    in.target_mask = mask->plane;
    in.target_mask_name = mask->name;
  }
  return r;
}

Image<float> gray_to_rgb(const Image<float>& gray) {
  CHECK_LE(gray.channels(), 2);
  const bool alpha = gray.channels() == 2;
  Image<float> out(gray.width(), gray.height(), alpha ? 4 : 3);
  for (int y = 0; y < gray.height(); ++y)
    for (int x = 0; x < gray.width(); ++x) {
      for (int c = 0; c < 3; ++c) out(x, y, c) = gray(x, y, 0);
      if (alpha) out(x, y, 3) = gray(x, y, 1);
    }
  return out;
}

}  // namespace emaki::synth
