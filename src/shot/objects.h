// A shot's scene opened: source.objects' asset files each loaded once (a file is what it is on
// disk: a symbolic link or another spelling of its path is the same file), each object's clip
// found and checked against the shot's frames, all placed into one scene (scene/assembly.h); or
// the one source.scene. Errors name source.objects[N].KEY or source.scene. Internal to the shot
// module.
#pragma once

#include <cstdint>

#include "pipeline/shot_description.h"
#include "scene/scene.h"

namespace emaki::shot {

// The most a shot's scene may hold in memory while it is opened: every distinct asset file's
// decoded textures and geometry, and each placement's copy of its asset's geometry (textures are
// shared). Over it, opening the scene is an error naming the object's key that takes it over,
// before that object's copy is made. The loader's limits per file (io/gltf_loader.h) allow about
// 1.2 GB for one file, so any single file fits.
inline constexpr int64_t kMaxSceneBytes = int64_t(2) << 30;

// What opening the scene costs, for the planner's memory estimate.
struct SceneCost {
  int64_t bytes = 0;                                // the peak charged against kMaxSceneBytes
  int64_t drawn_vertices = 0, drawn_triangles = 0;  // what the renderer poses per frame
};

// `budget`: kMaxSceneBytes (a test's smaller one shows where an object takes it over).
scene::Scene load_objects(const pipeline::Source& source, SceneCost* cost = nullptr,
                          int64_t budget = kMaxSceneBytes);
// The shot's scene (source.objects or source.scene), charged against kMaxSceneBytes.
scene::Scene load_scene(const pipeline::Source& source, SceneCost* cost = nullptr);

}  // namespace emaki::shot
