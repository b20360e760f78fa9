// The settings that made a shot's outputs, written beside them (store/output_store.h manifests):
// a layer's frames depend on the source frames, the exemplar and the layer's synthesis settings;
// the composited frames on the size and the layers' channel layout. Resuming compares them with
// the shot as it is now, so that a changed size or layer setting redoes the work instead of
// mixing old and new files.
#pragma once

#include "pipeline/shot_description.h"
#include "store/output_store.h"

namespace emaki::io {

// Bumped when emaki's output files change meaning (channel layout, synthesis algorithm).
inline constexpr int kOutputsFormat = 1;

Manifest layer_manifest(const pipeline::Shot& shot, const pipeline::Layer& layer);
Manifest frames_manifest(const pipeline::Shot& shot);
// The guide passes of a scene source's frames (the farm's pass cache, passes/frame_%04d.exr).
Manifest passes_manifest(const pipeline::Shot& shot);

}  // namespace emaki::io
