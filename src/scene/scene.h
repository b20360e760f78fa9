// The in-memory Scene: a glTF 2.0-shaped node hierarchy with triangle meshes, skins, morph
// targets, materials, cameras and animation clips, plus the evaluation of a clip at a time into
// posed world-space geometry. Nothing here reads files (io/gltf_loader fills a Scene).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <memory>
#include <string>
#include <vector>

#include "core/image.h"

namespace emaki::scene {

// A decoded texture: linear-light RGBA float (sRGB-encoded colour textures are decoded on load).
// Shared and immutable: an assembly (scene/assembly.h) that places one asset many times holds
// its textures once.
struct Texture {
  enum class Wrap { kRepeat, kClamp, kMirror };
  std::shared_ptr<const Image<float>> rgba;  // 4 channels, never null
  Wrap wrap_s = Wrap::kRepeat;
  Wrap wrap_t = Wrap::kRepeat;
};

struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};   // linear RGBA factor
  int base_color_texture = -1;  // index into Scene::textures, -1: none
  int texcoord = 0;             // which UV set the texture reads (only set 0 is kept)
};

struct MorphTarget {
  std::vector<glm::vec3> positions;  // displacements, one per vertex (may be empty)
  std::vector<glm::vec3> normals;    // displacements, one per vertex (may be empty)
};

// One indexed triangle list with its vertex attributes; all per-vertex arrays have the same
// length as positions (or are empty when the file has no such attribute).
struct Primitive {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::u16vec4> joints;  // indices into the node's Skin::joints
  std::vector<glm::vec4> weights;
  std::vector<uint32_t> indices;  // 3 per triangle
  std::vector<MorphTarget> targets;
  int material = -1;  // index into Scene::materials, -1: the default material
  // The rest_position pass's positions when they are not `positions` (empty: `positions`). An
  // assembly (scene/assembly.h) gives each asset's rest pose in the asset's own unit cube, so
  // that small and large assets keep the same precision in the pass.
  std::vector<glm::vec3> rest_positions;
};

struct Mesh {
  std::string name;
  std::vector<Primitive> primitives;
  std::vector<float> weights;  // default morph weights
};

struct Skin {
  std::string name;
  std::vector<int> joints;              // node indices
  std::vector<glm::mat4> inverse_bind;  // one per joint
};

struct CameraDef {
  std::string name;
  bool perspective = true;
  float yfov = 0.8f;               // radians (perspective)
  float xmag = 1.0f, ymag = 1.0f;  // half extents (orthographic)
  float znear = 0.01f;
};

struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  glm::vec3 scale{1.0f};
  // A node given by a matrix is not animatable (glTF rule); the matrix replaces T*R*S.
  bool has_matrix = false;
  glm::mat4 matrix{1.0f};
  int mesh = -1;
  int skin = -1;
  int camera = -1;
  std::vector<float> weights;  // morph weights overriding the mesh's defaults
  // Moves the node by t x velocity at time t (an assembly's object walking through the shot).
  glm::vec3 velocity{0.0f};
  // The object id of the mesh drawn here (PosedPrimitive::object_id); -1: the next in hierarchy
  // order. An assembly gives all of one asset's meshes its object's id.
  int object_id = -1;
};

enum class AnimPath { kTranslation, kRotation, kScale, kWeights };
enum class Interpolation { kLinear, kStep, kCubicSpline };

struct AnimSampler {
  std::vector<float> times;   // non-decreasing, finite keyframe times (seconds)
  std::vector<float> values;  // components per key (x3 for cubic spline: in, value, out)
  int components = 0;         // 3, 4 or the morph target count
  Interpolation interpolation = Interpolation::kLinear;
};

struct AnimChannel {
  int node = -1;
  AnimPath path = AnimPath::kTranslation;
  int sampler = -1;
  // The channel's own clock, for an animation that plays several clips at once (an assembly,
  // scene/assembly.h, plays each object's clip from its own start, looped or not): at time t
  // the sampler is read at time_base + x, x = t + time_offset wrapped into [0, loop_length)
  // when loop_length > 0 (in double, so frame f and f + one cycle land on the same time). A
  // file's own clips leave all three at 0: the sampler is read at t.
  double time_base = 0.0, time_offset = 0.0, loop_length = 0.0;
};

struct Animation {
  std::string name;
  std::vector<AnimSampler> samplers;
  std::vector<AnimChannel> channels;
  float start = 0.0f;  // earliest key time
  float end = 0.0f;    // latest key time
};

// Invariants the loader establishes (io/gltf_loader): the nodes form a forest (every child
// index is valid, no node has two parents, no cycles), roots are distinct parentless nodes,
// every index (mesh, skin, camera, material, joint, sampler) is in range and every number is
// finite.
struct Scene {
  std::string source;  // the file it was loaded from: the subject of errors about its content
  std::vector<Node> nodes;
  std::vector<int> roots;  // the nodes of the displayed glTF scene
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Skin> skins;
  std::vector<CameraDef> cameras;
  std::vector<Animation> animations;

  // Index of the clip called `name`, or -1.
  int find_animation(const std::string& name) const;
};

// What a scene holds in memory: its decoded textures (each shared image counted once) and its
// geometry (every mesh's vertex, index and morph arrays). The figure a scene budget is charged.
struct SceneBytes {
  int64_t textures = 0;
  int64_t geometry = 0;
  int64_t total() const { return textures + geometry; }
};
SceneBytes scene_bytes(const Scene& scene);
// Geometry bytes of one mesh primitive.
int64_t primitive_bytes(const Primitive& p);

// Samples one animation sampler at time t (clamped to its key range) into out[components].
// Rotations (components == 4 with slerp) are normalised quaternions stored x, y, z, w.
void sample(const AnimSampler& s, float t, bool is_rotation, float* out);

// Local transforms, world matrices and morph weights of every node at one time.
struct Pose {
  std::vector<glm::vec3> translation;
  std::vector<glm::quat> rotation;
  std::vector<glm::vec3> scale;
  std::vector<std::vector<float>> weights;  // per node; empty: the mesh defaults
  std::vector<glm::mat4> world;
};

// Evaluates clip `animation` (-1: the rest pose as stored in the nodes) at time t. Throws
// emaki::Error (subject: scene.source) when a world transform overflows to a non-finite value.
Pose evaluate_pose(const Scene& scene, int animation, float t);

// Posed positions further than this from the origin are refused: the renderer's squared
// distances and bounds stay finite (1e12 m is seven times the Earth-Sun distance).
inline constexpr float kMaxWorldCoordinate = 1e12f;

// One drawn mesh primitive posed at one time. object_id counts the drawn (node, mesh) pairs in
// hierarchy order from 0 unless the node gives its own (Node::object_id); material is the Scene
// material index (-1: default).
struct PosedPrimitive {
  int node = -1;
  int mesh = -1;
  int primitive = -1;
  int object_id = 0;
  int material = -1;
  std::vector<glm::vec3> world_positions;
  std::vector<glm::vec3> world_normals;                    // unit length
  const std::vector<glm::vec3>* rest_positions = nullptr;  // Primitive::rest_positions or bind pose
  const std::vector<glm::vec2>* uvs = nullptr;             // may be empty
  const std::vector<uint32_t>* indices = nullptr;
};

struct PosedScene {
  std::vector<PosedPrimitive> primitives;
  int object_count = 0;
};

// The world-space geometry of every mesh instance at time t of clip `animation` (-1: rest):
// node transforms, skinning (4 weights per vertex) and morph targets applied. Throws
// emaki::Error (subject: scene.source) when a posed position is not finite or lies beyond
// kMaxWorldCoordinate: finite inputs can still overflow through chained transforms.
PosedScene pose_scene(const Scene& scene, int animation, float t);

struct Bounds {
  glm::vec3 lo{1e30f};
  glm::vec3 hi{-1e30f};
  bool empty() const { return lo.x > hi.x; }
  void add(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void add(const Bounds& b) {
    if (!b.empty()) add(b.lo), add(b.hi);
  }
  glm::vec3 center() const { return 0.5f * (lo + hi); }
  glm::vec3 size() const { return hi - lo; }
};

Bounds world_bounds(const PosedScene& posed);
// Bounds of the rest (bind-pose, object-space) positions of every drawn primitive.
Bounds rest_bounds(const PosedScene& posed);

}  // namespace emaki::scene
