// A scene assembled from several scenes (a shot file's source.objects): each asset placed by its
// own transform and moved by its own velocity, playing its own clip from its own start, looped
// or not, with all the meshes it draws under one object id. The result is one Scene with one
// clip, kAssemblyClip, that plays every object's clip at once: time t of that clip is t seconds
// into the shot (frame f at f / fps). Ids stay unique across assets: every asset brings its own
// materials (and its own default material when a primitive has none), and its object id is the
// caller's. Nothing here reads files.
#pragma once

#include <glm/glm.hpp>
#include <span>

#include "scene/scene.h"

namespace emaki::scene {

inline constexpr const char* kAssemblyClip = "assembly";
// The assembly's clip runs from 0 to this (seconds): it has no end of its own, each object's
// clip is checked by whoever chose it.
inline constexpr float kAssemblyClipEnd = 1e6f;

struct Placement {
  const Scene* asset = nullptr;
  glm::vec3 translate{0.0f};
  glm::vec3 rotate_deg{0.0f};  // about the X, then the Y, then the Z axis (world axes), degrees
  glm::vec3 scale{1.0f};
  glm::vec3 velocity{0.0f};  // world units per second: at time t the object is moved by t x this
  int animation = -1;        // the asset's clip; -1: its rest pose
  double start = 0.0;        // seconds into the clip (after its first key) at time 0
  bool loop = false;         // the clip's time wraps around its length
  int object_id = 0;         // PosedPrimitive::object_id of every mesh it draws
};

// translate * rotate * scale: where the asset stands at time 0.
glm::mat4 placement_matrix(const Placement& p);

// The objects in one scene. An asset placed several times shares its textures between its
// placements (its meshes are copied per placement). Each asset's rest positions
// (Primitive::rest_positions) are its rest pose — posed node transforms, bind pose for skinned
// meshes — in the unit cube around it, so the rest_position pass of a small prop keeps the
// precision of a large one; a mesh that an asset draws from several nodes is copied per node.
Scene assemble(std::span<const Placement> objects);

}  // namespace emaki::scene
