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
// Every manifest's line `emaki_version = 0.1.0+g...` (core/version.h): the emaki that recorded
// the settings. Informative only: the comparison leaves it out (kOutputsFormat is what makes a
// new emaki redo old outputs), and older manifests without it are current.
inline constexpr const char* kVersionKey = "emaki_version";

Manifest layer_manifest(const pipeline::Shot& shot, const pipeline::Layer& layer);
Manifest frames_manifest(const pipeline::Shot& shot);
// The guide passes of a scene source's frames (the farm's pass cache, passes/frame_%04d.exr).
Manifest passes_manifest(const pipeline::Shot& shot);

// What a MatCap-like exemplar's reference passes at width x height (its painting's size) are
// rendered from: the sphere, camera, light and anti-aliasing (store/reference_cache.h).
Manifest reference_manifest(const pipeline::Exemplar& exemplar, int width, int height);

// Whether files made under the manifest `have` (read from disk) are current for `want`. Inputs
// are told apart by what they are, never by how a path to them was spelled: an input file's path
// line is left out of the comparison wherever a `KEY.digest` line beside it holds the file's
// content digest, and a sequence's pattern is compared as a canonical path (symbolic links
// resolved). `emaki run shot.toml`, `emaki run $PWD/shot.toml`, a path through a linked folder
// and a farm's absolute paths so all find the same outputs current.
bool manifest_current(const Manifest& have, const Manifest& want);
// What changed from `have` to `want` (manifest_difference on what manifest_current compares);
// empty when current.
std::string manifest_change(const Manifest& have, const Manifest& want);

}  // namespace emaki::io
