// A shot's inputs, opened: its frames (rendered from a glTF scene, or read from a studio render's
// EXR sequence), its exemplars' paintings and guide passes, and the paper. Errors from the
// loaders below name the shot file's keys (source.clip, exemplars.NAME.sphere, ...).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "pipeline/shot_description.h"
#include "shot/input_cache.h"

namespace emaki::shot {

// Each loader takes an optional InputCache (shot/input_cache.h): what it holds for unchanged
// files and settings is taken from it instead of being read, decoded or rendered again.

std::unique_ptr<pipeline::FrameSource> open_frames(const pipeline::Shot& shot,
                                                   InputCache* cache = nullptr);

// Every exemplar's painting and guide passes; errors name exemplars.NAME.*. With `rendered`, a
// MatCap-like exemplar's reference passes are read from the shot's output folder when a task or
// run kept them there (store/reference_cache.h), and the exemplars whose passes had to be
// rendered are added to it, for keep_references once the output folder is locked.
std::map<std::string, pipeline::ExemplarImages> load_exemplars(
    const pipeline::Shot& shot, std::vector<std::string>* rendered = nullptr,
    InputCache* cache = nullptr);

// Keeps the `rendered` exemplars' reference passes in the shot's output folder.
void keep_references(const pipeline::Shot& shot,
                     const std::map<std::string, pipeline::ExemplarImages>& exemplars,
                     const std::vector<std::string>& rendered);

pipeline::CompositeInputs load_composite_inputs(const pipeline::Shot& shot,
                                                InputCache* cache = nullptr);

// Every painted guide weight map the layers name (first channel); errors name
// layers.NAME.guides.PASS.map (a map that is not the shot's size).
pipeline::WeightMapImages load_weight_maps(const pipeline::Shot& shot, InputCache* cache = nullptr);

}  // namespace emaki::shot
