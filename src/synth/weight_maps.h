// Per-pixel guide weights (GuidePair::weight_map) inside the engine: which feature channels each
// map weighs (channel groups), the maps gathered over the target, and each target pixel's group
// weights for the grouped distance kernel. Internal to the synth module.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "synth/pyramid.h"
#include "synth/synthesizer.h"

namespace emaki::synth {

// Throws emaki::Error naming the map when one does not fit the tw x th target (its size; its
// values finite and in [0, 1]), and naming the guides or the patch size when the grouped sums
// could leave 64 bits (more than kMaxWeightMaps maps; patch area x channels above 2^19).
void check_weight_maps(const Inputs& in, const Params& params, int tw, int th);

// Throws emaki::Error naming `name` when the map is not tw x th or a value of its first channel is
// not in [0, 1] (a guide's weight map, Params::uniformity_map).
void check_unit_map(const Plane& map, const std::string& name, int tw, int th);

// The map's first channel, tw x th.
Image<float> gather_map(const Plane& map, int tw, int th);

// Puts each mapped guide's channels in a group of their own (group k for the k-th map, group 0
// for the rest), makes the groups' masks for patch_size and turns err_scale into the grouped
// distance's units.
void assign_channel_groups(const Inputs& in, int patch_size, FeatureLayout& layout);

// The maps' first channels, tw x th x (number of maps), in guide order.
Image<float> gather_weight_maps(const Inputs& in, int tw, int th);

// Each pixel's group weights: group 0 at kGroupWeightOne, the maps quantised to steps of
// 1 / kGroupWeightOne.
Image<int64_t> quantize_group_weights(const Image<float>& maps);

}  // namespace emaki::synth
