// temporal_bench's variant modifiers: the `:key=value` suffixes of a variant's name, each a
// setting of the layer's pipeline::TemporalSpec.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pipeline/shot_description.h"

namespace emaki::bench {

// The `:key=value` modifiers of a variant: s=SIGMA (temporal guide_sigma; unset: from the frame's
// size against the painting's), x=X (warm start's sharp estimate; unset: 0, -1: as the sigma),
// u=U (uniformity), w=W (weight), c=FULL/NONE (the guide-change ramp), r=0|1 (reseed), im=SHARE,
// is=SIGMA (TemporalSpec::ink_match, ink_sigma), ir=SHARE, ig=PASS, ib=BINS, ic=W, ik=FRAMES,
// io=0|1, iv=0|1 (ink_ratio, ink_guide, ink_bins, ink_confident, ink_refresh, ink_objects,
// ink_blend), fu=U, fr=RADIUS, ft=TOLERANCE (flat_uniformity, flat), cr=R (coherence_radius).
// Throws std::invalid_argument naming a modifier it does not know.
inline void apply_modifiers(pipeline::Layer& l, const std::string& variant) {
  std::stringstream ss(variant.substr(std::min(variant.size(), variant.find(':'))));
  for (std::string m; std::getline(ss, m, ':');) {
    if (m.empty()) continue;
    const std::size_t eq = m.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("bad modifier " + m);
    const std::string key = m.substr(0, eq), value = m.substr(eq + 1);
    const float x = std::strtof(value.c_str(), nullptr);
    if (key == "s") {
      l.temporal.guide_sigma = x;
    } else if (key == "x") {
      l.temporal.sharp_estimate = x;
    } else if (key == "u") {
      l.temporal.uniformity = x;
    } else if (key == "w") {
      l.temporal.weight = x;
    } else if (key == "c") {
      l.temporal.confidence_params.change_full = x;
      l.temporal.confidence_params.change_none =
          std::strtof(value.c_str() + value.find('/') + 1, nullptr);
    } else if (key == "r") {
      l.temporal.reseed = x != 0.0f;
    } else if (key == "a") {
      l.temporal.anchor = int(x);
    } else if (key == "as") {
      l.temporal.anchor_sigma = x;
    } else if (key == "ah") {
      l.temporal.anchor_holes = x != 0.0f;
    } else if (key == "fu") {
      l.temporal.flat_uniformity = x;
    } else if (key == "fr") {
      l.temporal.flat.area_radius = int(x);
    } else if (key == "ft") {
      l.temporal.flat.tolerance = x;
    } else if (key == "im") {
      l.temporal.ink_match = x;
    } else if (key == "ir") {
      l.temporal.ink_ratio = x;
    } else if (key == "ig") {
      l.temporal.ink_guide = value;
    } else if (key == "ib") {
      l.temporal.ink_bins = int(x);
    } else if (key == "ik") {
      l.temporal.ink_refresh = int(x);
    } else if (key == "iv") {
      l.temporal.ink_blend = x != 0.0f;
    } else if (key == "io") {
      l.temporal.ink_objects = x != 0.0f;
    } else if (key == "ic") {
      l.temporal.ink_confident = x;
    } else if (key == "is") {
      l.temporal.ink_sigma = x;
    } else if (key == "ar") {
      l.temporal.anchor_rate = x;
    } else if (key == "e") {
      l.temporal.confidence_params.erode = int(x);
    } else if (key == "fi") {
      l.temporal.finest_iters = int(x);
    } else if (key == "ai") {
      l.temporal.anchor_finest_iters = int(x);
    } else if (key == "pm") {
      l.temporal.warm_patch_match_iters = int(x);
    } else if (key == "cr") {
      l.temporal.coherence_radius = int(x);
    } else {
      throw std::invalid_argument("bad modifier " + m);
    }
  }
}

}  // namespace emaki::bench
