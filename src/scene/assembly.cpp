#include "scene/assembly.h"

#include <algorithm>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <map>

#include "core/check.h"

namespace emaki::scene {

namespace {

glm::quat rotation_of(const glm::vec3& deg) {
  const glm::vec3 r = glm::radians(deg);
  return glm::angleAxis(r.z, glm::vec3(0, 0, 1)) * glm::angleAxis(r.y, glm::vec3(0, 1, 0)) *
         glm::angleAxis(r.x, glm::vec3(1, 0, 0));
}

int shifted(int index, int base) {
  return index >= 0 ? index + base : index;
}

// Where an asset's arrays start in the assembled scene.
struct Offsets {
  int node, mesh, material, texture, skin, camera;
};

// The asset's materials, meshes, skins and cameras appended to `out` (its textures are already
// there, from `o.texture` on: shared by every placement of the asset). A primitive without a
// material gets the asset's own white default, so no two assets share a material id.
void append_data(const Scene& a, const Offsets& o, Scene& out) {
  for (Material m : a.materials) {
    m.base_color_texture = shifted(m.base_color_texture, o.texture);
    out.materials.push_back(m);
  }
  int default_material = -1;
  for (Mesh m : a.meshes) {
    for (Primitive& p : m.primitives) {
      if (p.material < 0 && default_material < 0) {
        default_material = int(out.materials.size());
        out.materials.push_back({"default", glm::vec4(1.0f), -1, 0});
      }
      p.material = p.material >= 0 ? p.material + o.material : default_material;
    }
    out.meshes.push_back(std::move(m));
  }
  for (Skin s : a.skins) {
    for (int& j : s.joints) j += o.node;
    out.skins.push_back(std::move(s));
  }
  out.cameras.insert(out.cameras.end(), a.cameras.begin(), a.cameras.end());
}

void append_nodes(const Scene& a, const Offsets& o, int object_id, Scene& out) {
  for (Node n : a.nodes) {
    n.parent = shifted(n.parent, o.node);
    for (int& c : n.children) c += o.node;
    n.mesh = shifted(n.mesh, o.mesh);
    n.skin = shifted(n.skin, o.skin);
    n.camera = shifted(n.camera, o.camera);
    if (n.mesh >= 0) n.object_id = object_id;
    out.nodes.push_back(std::move(n));
  }
}

// A parentless node carrying the placement, over `children` (assembled indices, parentless).
void add_placement_node(const Placement& p, const std::vector<int>& children, Scene& out) {
  Node n;
  n.name = "placement";
  n.translation = p.translate;
  n.rotation = rotation_of(p.rotate_deg);
  n.scale = p.scale;
  n.velocity = p.velocity;
  n.children = children;
  const int index = int(out.nodes.size());
  for (int c : children) out.nodes[c].parent = index;
  out.nodes.push_back(std::move(n));
}

// The asset's drawn meshes, in the order pose_scene draws them: each node gets a mesh of its own
// (copied when another node drew it first) whose rest positions are the asset's rest pose in the
// unit cube around it.
void set_rest_positions(const Scene& a, const Offsets& o, Scene& out) {
  const Pose rest = evaluate_pose(a, -1, 0.0f);
  std::vector<char> drawn(a.meshes.size(), 0);
  std::vector<int> nodes;
  std::vector<int> stack(a.roots.rbegin(), a.roots.rend());
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const Node& node = a.nodes[i];
    if (node.mesh >= 0) {
      if (drawn[node.mesh]) {
        Mesh copy = out.meshes[o.mesh + node.mesh];
        out.nodes[o.node + i].mesh = int(out.meshes.size());
        out.meshes.push_back(std::move(copy));
      }
      drawn[node.mesh] = 1;
      nodes.push_back(i);
    }
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.push_back(*it);
  }
  Bounds bounds;
  for (int i : nodes) {
    const Node& node = a.nodes[i];
    for (Primitive& p : out.meshes[out.nodes[o.node + i].mesh].primitives) {
      const std::size_t nv = p.positions.size();
      // glTF: a skinned mesh's vertices are in its bind pose already, whatever its node.
      const bool skinned = node.skin >= 0 && p.joints.size() == nv && p.weights.size() == nv;
      p.rest_positions.resize(nv);
      for (std::size_t v = 0; v < nv; ++v) {
        p.rest_positions[v] =
            skinned ? p.positions[v] : glm::vec3(rest.world[i] * glm::vec4(p.positions[v], 1.0f));
        bounds.add(p.rest_positions[v]);
      }
    }
  }
  if (bounds.empty()) return;
  const float side = std::max({bounds.size().x, bounds.size().y, bounds.size().z, 1e-20f});
  const glm::vec3 lo = bounds.center() - 0.5f * side;
  for (int i : nodes)
    for (Primitive& p : out.meshes[out.nodes[o.node + i].mesh].primitives)
      for (glm::vec3& r : p.rest_positions) r = (r - lo) / side;
}

// The object's clip, on its own clock.
void add_clip(const Placement& p, const Offsets& o, Animation& out) {
  if (p.animation < 0) return;
  const Animation& clip = p.asset->animations.at(p.animation);
  const int sampler_base = int(out.samplers.size());
  out.samplers.insert(out.samplers.end(), clip.samplers.begin(), clip.samplers.end());
  const double length = double(clip.end) - clip.start;
  for (AnimChannel ch : clip.channels) {
    ch.node += o.node;
    ch.sampler += sampler_base;
    ch.time_base = clip.start;
    ch.time_offset = p.start;
    ch.loop_length = p.loop && length > 0.0 ? length : 0.0;
    out.channels.push_back(ch);
  }
}

}  // namespace

glm::mat4 placement_matrix(const Placement& p) {
  return glm::translate(glm::mat4(1.0f), p.translate) * glm::mat4_cast(rotation_of(p.rotate_deg)) *
         glm::scale(glm::mat4(1.0f), p.scale);
}

Scene assemble(std::span<const Placement> objects) {
  Scene out;
  out.source = "assembly";
  Animation clip;
  clip.name = kAssemblyClip;
  clip.start = 0.0f;
  clip.end = kAssemblyClipEnd;
  // Where each asset's textures start: an asset placed many times (a crowd of one character)
  // holds its textures once, shared, however many placements draw them.
  std::map<const Scene*, int> textures_at;
  for (const Placement& p : objects) {
    CHECK(p.asset != nullptr);
    const Scene& a = *p.asset;
    const auto [at, first] = textures_at.try_emplace(&a, int(out.textures.size()));
    if (first) out.textures.insert(out.textures.end(), a.textures.begin(), a.textures.end());
    const Offsets o{int(out.nodes.size()),     int(out.meshes.size()),
                    int(out.materials.size()), at->second,
                    int(out.skins.size()),     int(out.cameras.size())};
    append_data(a, o, out);
    append_nodes(a, o, p.object_id, out);
    set_rest_positions(a, o, out);
    // Every parentless node of the asset goes under a placement node, which is not drawn itself:
    // the asset's displayed roots (which may have parents: exporters list child nodes as roots)
    // stay the roots, now posed through it.
    std::vector<int> parentless;
    for (int i = 0; i < int(a.nodes.size()); ++i)
      if (a.nodes[i].parent < 0) parentless.push_back(i + o.node);
    add_placement_node(p, parentless, out);
    for (int r : a.roots) out.roots.push_back(r + o.node);
    add_clip(p, o, clip);
  }
  out.animations.push_back(std::move(clip));
  return out;
}

}  // namespace emaki::scene
