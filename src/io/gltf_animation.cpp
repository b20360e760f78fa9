// Animations (Loader members, see gltf_internal.h). Key times are checked finite, bounded and
// non-decreasing, and each channel's values per key against what it animates, so that sampling
// a pose later cannot fail.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/limits.h"
#include "io/gltf_internal.h"

namespace emaki::io::gltf_detail {

void Loader::load_animations(Scene& s) {
  for (std::size_t ai = 0; ai < m_.animations.size(); ++ai) {
    const tinygltf::Animation& anim = m_.animations[ai];
    scene::Animation out;
    out.name = anim.name.empty() ? fmt::format("animation{}", ai) : anim.name;
    const std::string label = fmt::format("animation {} ('{}')", ai, echo(out.name));
    out.start = 1e30f;
    out.end = -1e30f;
    for (const auto& ch : anim.channels) {
      if (ch.sampler < 0 || std::size_t(ch.sampler) >= anim.samplers.size())
        fail(fmt::format("{} channel refers to sampler {}", label, ch.sampler));
      if (ch.target_node < 0 || std::size_t(ch.target_node) >= m_.nodes.size())
        fail(fmt::format("{} channel targets node {}", label, ch.target_node));
    }
    for (std::size_t si = 0; si < anim.samplers.size(); ++si) {
      scene::AnimSampler smp =
          load_sampler(anim.samplers[si], fmt::format("{} sampler {}", label, si));
      out.start = std::min(out.start, smp.times.front());
      out.end = std::max(out.end, smp.times.back());
      out.samplers.push_back(std::move(smp));
    }
    for (const auto& ch : anim.channels) {
      scene::AnimChannel c;
      c.node = ch.target_node;
      c.sampler = ch.sampler;
      int need = 3;
      if (ch.target_path == "translation") {
        c.path = scene::AnimPath::kTranslation;
      } else if (ch.target_path == "rotation") {
        c.path = scene::AnimPath::kRotation;
        need = 4;
      } else if (ch.target_path == "scale") {
        c.path = scene::AnimPath::kScale;
      } else if (ch.target_path == "weights") {
        c.path = scene::AnimPath::kWeights;
        need = -1;
      } else {
        continue;  // extension paths (KHR_animation_pointer) are not ours
      }
      const int comps = out.samplers[ch.sampler].components;
      if (need > 0 && comps != need)
        fail(fmt::format("{} {} channel has {} components per key, expected {}", label,
                         ch.target_path, comps, need));
      if (s.nodes[c.node].has_matrix)
        fail(fmt::format("{} animates node {}, which is given by a matrix", label, c.node));
      out.channels.push_back(c);
    }
    if (out.samplers.empty()) out.start = out.end = 0.0f;
    s.animations.push_back(std::move(out));
  }
}

// One sampler's key times and values; `what` names it in errors.
scene::AnimSampler Loader::load_sampler(const tinygltf::AnimationSampler& in,
                                        const std::string& what) {
  scene::AnimSampler smp;
  smp.times = read_floats(in.input, 1, what + " input");
  if (smp.times.empty()) fail(what + " has no keyframes");
  for (std::size_t k = 0; k < smp.times.size(); ++k) {
    if (!(std::abs(smp.times[k]) <= kMaxKeyTime))
      fail(fmt::format("{} has key time {} s (key times must be finite and within ±{} s)", what,
                       smp.times[k], kMaxKeyTime));
    if (k > 0 && !(smp.times[k] >= smp.times[k - 1]))
      fail(fmt::format("{} has key times that decrease ({} s after {} s)", what, smp.times[k],
                       smp.times[k - 1]));
  }
  smp.values = read_floats(in.output, 0, what + " output");
  smp.interpolation = in.interpolation == "STEP"          ? scene::Interpolation::kStep
                      : in.interpolation == "CUBICSPLINE" ? scene::Interpolation::kCubicSpline
                                                          : scene::Interpolation::kLinear;
  const std::size_t keys =
      smp.times.size() * (smp.interpolation == scene::Interpolation::kCubicSpline ? 3 : 1);
  if (smp.values.size() % keys != 0 || smp.values.empty())
    fail(fmt::format("{} output has {} values for {} keys", what, smp.values.size(), keys));
  if (smp.values.size() / keys > std::size_t(kMaxMorphTargets))
    fail(fmt::format("{} output has {} values per key (at most {})", what, smp.values.size() / keys,
                     kMaxMorphTargets));
  smp.components = int(smp.values.size() / keys);
  return smp;
}

}  // namespace emaki::io::gltf_detail
