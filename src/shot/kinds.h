// The shot file's names for emaki's enums, and what each layer kind means (its defaults).
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "composite/composite.h"
#include "pipeline/shot_description.h"
#include "scene/staging.h"

namespace emaki::shot {

// An enum value as the shot file spells it.
template <typename E>
struct Named {
  std::string_view name;
  E value;
};

inline constexpr Named<pipeline::LayerKind> kLayerKinds[] = {
    {"base", pipeline::LayerKind::kBase},     {"outline", pipeline::LayerKind::kOutline},
    {"shadow", pipeline::LayerKind::kShadow}, {"hatching", pipeline::LayerKind::kHatching},
    {"custom", pipeline::LayerKind::kCustom},
};
inline constexpr Named<pipeline::SourcePreset> kSourcePresets[] = {
    {"emaki", pipeline::SourcePreset::kEmaki},
    {"blender", pipeline::SourcePreset::kBlender},
};
inline constexpr Named<pipeline::CompositingSpace> kCompositingSpaces[] = {
    {"display", pipeline::CompositingSpace::kDisplay},
    {"scene_linear", pipeline::CompositingSpace::kSceneLinear},
};
inline constexpr Named<pipeline::ExemplarKind> kExemplarKinds[] = {
    {"matcap", pipeline::ExemplarKind::kMatcap},
    {"keyframe", pipeline::ExemplarKind::kKeyframe},
};
inline constexpr Named<scene::CameraSpec::Mode> kCameraModes[] = {
    {"auto", scene::CameraSpec::Mode::kAuto},
    {"look_at", scene::CameraSpec::Mode::kLookAt},
    {"gltf", scene::CameraSpec::Mode::kGltf},
};
inline constexpr Named<pipeline::MaskKind> kMaskKinds[] = {
    {"none", pipeline::MaskKind::kNone},       {"covered", pipeline::MaskKind::kCovered},
    {"objects", pipeline::MaskKind::kObjects}, {"lines", pipeline::MaskKind::kLines},
    {"shadow", pipeline::MaskKind::kShadow},   {"lit", pipeline::MaskKind::kLit},
};
inline constexpr Named<pipeline::AdvectionGuide> kAdvectionGuides[] = {
    {"position", pipeline::AdvectionGuide::kPosition},
    {"rest_position", pipeline::AdvectionGuide::kRestPosition},
};
// layers.NAME.temporal_fields: true keeps every frame's warm-start field, false the last one.
inline constexpr Named<bool> kKeptFields[] = {
    {"every", true},
    {"last", false},
};
inline constexpr Named<composite::BlendMode> kBlendModes[] = {
    {"normal", composite::BlendMode::kNormal},
    {"multiply", composite::BlendMode::kMultiply},
    {"screen", composite::BlendMode::kScreen},
    {"overlay", composite::BlendMode::kOverlay},
};
inline constexpr Named<composite::AlphaFrom> kAlphaFroms[] = {
    {"mask", composite::AlphaFrom::kMask},
    {"value", composite::AlphaFrom::kValue},
    {"inverse_value", composite::AlphaFrom::kInverseValue},
};
// `color` as a string; an [r, g, b] array is kFlat.
inline constexpr Named<composite::ColorSource> kColorSources[] = {
    {"albedo", composite::ColorSource::kAlbedo},
    {"gradient", composite::ColorSource::kGradient},
};
// The painting channel a single-colour layer takes its touch from (-1: luminance).
inline constexpr Named<int> kTouchChannels[] = {{"luminance", -1}, {"r", 0}, {"g", 1}, {"b", 2}};

// source.normals and source.up: whether the file's normals are world-space, its up axis Z.
inline constexpr Named<bool> kNormalSpaces[] = {{"camera", false}, {"world", true}};
inline constexpr Named<bool> kUpAxes[] = {{"y", false}, {"z", true}};

template <typename E>
std::string_view name_of(std::span<const Named<E>> names, E value) {
  for (const Named<E>& n : names)
    if (n.value == value) return n.name;
  return {};
}
template <typename E, std::size_t N>
std::string_view name_of(const Named<E> (&names)[N], E value) {
  return name_of(std::span<const Named<E>>(names), value);
}

template <typename E, std::size_t N>
std::vector<std::string> names_of(const Named<E> (&names)[N]) {
  std::vector<std::string> out;
  for (const Named<E>& n : names) out.emplace_back(n.name);
  return out;
}

// What a layer kind sets unless the layer says otherwise.
struct KindDefaults {
  std::vector<pipeline::GuideSpec> guides;
  pipeline::MaskSpec mask;
  composite::LayerLook look;
  float temporal_weight = 1.0f;
  float temporal_uniformity = 1000.0f;
  // The tone anchor's halvings (pipeline::TemporalSpec::anchor; not a shot-file key).
  int temporal_anchor = 2;
  // Whether temporal frames add the layer's own `uniformity` (the first frame's) inside large
  // flat areas of its guides (TemporalSpec::flat_uniformity; not a shot-file key).
  bool temporal_flat_uniformity = false;
  // Every how many frames temporal frames re-measure the mean ink per covered pixel they are
  // pinned to on a fresh transfer (TemporalSpec::ink_refresh, with ink_ratio 1; 0: no pin), and
  // how much each pixel's move follows the temporal guide's confidence (ink_confident). Not
  // shot-file keys.
  int temporal_ink_refresh = 0;
  float temporal_ink_confident = 0.0f;
  // Whether the pin is per object, its reference blended between refresh frames
  // (TemporalSpec::ink_objects and ink_blend; not shot-file keys).
  bool temporal_ink_objects = false;
  // Whether the warm start's carried field is made coherent again over a window that grows with
  // the frame's size against the painting's (TemporalSpec::coherence_radius -1; not a shot-file
  // key).
  bool temporal_coherence = false;
  // PatchMatch sweeps in the warm start's search-vote iteration (TemporalSpec::
  // warm_patch_match_iters; not a shot-file key).
  int temporal_warm_sweeps = 2;
};

KindDefaults kind_defaults(pipeline::LayerKind kind);

}  // namespace emaki::shot
