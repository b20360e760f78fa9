// Skins, cameras and the node forest (Loader members, see gltf_internal.h). Nodes are checked to
// form a forest (one parent each, no cycles) so that everything after can walk it without a
// visited set, and the scene's roots are chosen so that no node is drawn twice.
#include <fmt/format.h>

#include <algorithm>
#include <cstring>

#include "core/limits.h"
#include "io/gltf_internal.h"

namespace emaki::io::gltf_detail {

void Loader::load_skins(Scene& s) {
  for (std::size_t si = 0; si < m_.skins.size(); ++si) {
    const tinygltf::Skin& skin = m_.skins[si];
    scene::Skin out;
    out.name = skin.name;
    if (skin.joints.size() > std::size_t(kMaxSkinJoints))
      fail(fmt::format("skin {} has {} joints (at most {})", si, skin.joints.size(),
                       kMaxSkinJoints));
    for (int j : skin.joints) {
      if (j < 0 || std::size_t(j) >= m_.nodes.size())
        fail(fmt::format("skin {} refers to node {}, but the file has {}", si, j, m_.nodes.size()));
      out.joints.push_back(j);
    }
    if (skin.inverseBindMatrices >= 0) {
      const std::vector<float> f =
          read_floats(skin.inverseBindMatrices, 16, fmt::format("skin {} inverseBindMatrices", si));
      if (f.size() / 16 < out.joints.size())
        fail(fmt::format("skin {} has {} inverse bind matrices for {} joints", si, f.size() / 16,
                         out.joints.size()));
      for (std::size_t j = 0; j < out.joints.size(); ++j) {
        glm::mat4 m;
        std::memcpy(&m[0][0], f.data() + 16 * j, 16 * sizeof(float));  // column-major both
        out.inverse_bind.push_back(m);
      }
    } else {
      out.inverse_bind.assign(out.joints.size(), glm::mat4(1.0f));
    }
    s.skins.push_back(std::move(out));
  }
}

void Loader::load_cameras(Scene& s) {
  for (std::size_t ci = 0; ci < m_.cameras.size(); ++ci) {
    const tinygltf::Camera& c = m_.cameras[ci];
    scene::CameraDef def;
    def.name = c.name;
    def.perspective = c.type != "orthographic";
    bool ok;
    if (def.perspective) {
      ok = finite_float(c.perspective.yfov) && c.perspective.yfov > 0.0 &&
           c.perspective.yfov < 3.14159 && finite_float(c.perspective.znear) &&
           c.perspective.znear > 0.0;
      def.yfov = float(c.perspective.yfov);
      def.znear = float(c.perspective.znear);
    } else {
      ok = finite_float(c.orthographic.xmag) && c.orthographic.xmag != 0.0 &&
           finite_float(c.orthographic.ymag) && c.orthographic.ymag != 0.0 &&
           finite_float(c.orthographic.znear) && c.orthographic.znear >= 0.0;
      def.xmag = float(c.orthographic.xmag);
      def.ymag = float(c.orthographic.ymag);
      def.znear = float(c.orthographic.znear);
    }
    if (!ok)
      fail(fmt::format("camera {} ('{}') has an invalid field of view, magnification or znear", ci,
                       echo(c.name)));
    s.cameras.push_back(def);
  }
}

// The node forest: each node's transform and references, then the hierarchy's checks, then the
// roots drawn.
void Loader::load_nodes(Scene& s) {
  const int n = int(m_.nodes.size());
  s.nodes.resize(n);
  for (int i = 0; i < n; ++i) load_node(s, i);
  check_no_cycles(s);
  check_skinned_joints(s);
  find_roots(s);
}

// Node i's transform, references and children; a child already claimed by another parent
// fails here (s.nodes is sized for every node, so children ahead of i can be claimed).
void Loader::load_node(Scene& s, int i) {
  const int n = int(m_.nodes.size());
  const tinygltf::Node& in = m_.nodes[i];
  scene::Node& node = s.nodes[i];
  node.name = in.name;
  auto finite_all = [&](const std::vector<double>& v, const char* what) {
    for (double d : v)
      if (!finite_float(d))
        fail(fmt::format("node {} ('{}') has a non-finite {}", i, echo(in.name), what));
  };
  finite_all(in.translation, "translation");
  finite_all(in.rotation, "rotation");
  finite_all(in.scale, "scale");
  finite_all(in.matrix, "matrix");
  finite_all(in.weights, "morph weight");
  if (in.translation.size() == 3)
    node.translation = glm::vec3(in.translation[0], in.translation[1], in.translation[2]);
  if (in.rotation.size() == 4)
    node.rotation = glm::quat(float(in.rotation[3]), float(in.rotation[0]), float(in.rotation[1]),
                              float(in.rotation[2]));
  if (in.scale.size() == 3) node.scale = glm::vec3(in.scale[0], in.scale[1], in.scale[2]);
  if (in.matrix.size() == 16) {
    node.has_matrix = true;
    for (int k = 0; k < 16; ++k) node.matrix[k / 4][k % 4] = float(in.matrix[k]);
  }
  auto check_ref = [&](int ref, std::size_t count, const char* what) {
    if (ref >= 0 && std::size_t(ref) >= count)
      fail(fmt::format("node {} refers to {} {}, but the file has {}", i, what, ref, count));
  };
  check_ref(in.mesh, s.meshes.size(), "mesh");
  check_ref(in.skin, s.skins.size(), "skin");
  check_ref(in.camera, s.cameras.size(), "camera");
  node.mesh = std::max(in.mesh, -1);
  node.skin = std::max(in.skin, -1);
  node.camera = std::max(in.camera, -1);
  for (double w : in.weights) node.weights.push_back(float(w));
  for (int c : in.children) {
    if (c < 0 || c >= n)
      fail(fmt::format("node {} lists child {}, but the file has {} nodes", i, c, n));
    if (c == i) fail(fmt::format("node {} lists itself as a child", i));
    if (s.nodes[c].parent >= 0)
      fail(
          fmt::format("node {} has two parents (nodes {} and {}); the node hierarchy must "
                      "be a tree",
                      c, s.nodes[c].parent, i));
    node.children.push_back(c);
    s.nodes[c].parent = i;
  }
}

// With one parent per node, the hierarchy has a cycle exactly when walking up from some node
// never reaches a root. Each node is walked once: O(nodes).
void Loader::check_no_cycles(const Scene& s) const {
  const int n = int(s.nodes.size());
  std::vector<char> state(n, 0);  // 0: not seen, 1: on the current walk, 2: reaches a root
  std::vector<int> walk;
  for (int i = 0; i < n; ++i) {
    walk.clear();
    int j = i;
    while (j >= 0 && state[j] == 0) {
      state[j] = 1;
      walk.push_back(j);
      j = s.nodes[j].parent;
    }
    if (j >= 0 && state[j] == 1)
      fail(fmt::format("node {} is its own ancestor: the node hierarchy has a cycle", j));
    for (int k : walk) state[k] = 2;
  }
}

// Joint indices must stay inside the skin the mesh is drawn with.
void Loader::check_skinned_joints(const Scene& s) const {
  for (std::size_t i = 0; i < s.nodes.size(); ++i) {
    const scene::Node& node = s.nodes[i];
    if (node.mesh < 0 || node.skin < 0) continue;
    const std::size_t joints = s.skins[node.skin].joints.size();
    for (const auto& p : s.meshes[node.mesh].primitives)
      for (const auto& j : p.joints)
        for (int c = 0; c < 4; ++c)
          if (j[c] >= joints)
            fail(fmt::format("mesh {} uses joint {} but skin {} has {} joints", node.mesh, j[c],
                             node.skin, joints));
  }
}

// The default scene's nodes (each listed once), or every parentless node when the file has no
// scene.
void Loader::find_roots(Scene& s) const {
  const int n = int(s.nodes.size());
  const int scene_index = m_.defaultScene >= 0 ? m_.defaultScene : 0;
  if (std::size_t(scene_index) >= m_.scenes.size()) {
    for (int i = 0; i < n; ++i)
      if (s.nodes[i].parent < 0) s.roots.push_back(i);
    return;
  }
  std::vector<char> listed(n, 0);
  for (int r : m_.scenes[scene_index].nodes) {
    if (r < 0 || r >= n)
      fail(fmt::format("scene {} refers to node {}, but the file has {} nodes", scene_index, r, n));
    if (listed[r]) fail(fmt::format("scene {} lists node {} twice", scene_index, r));
    listed[r] = 1;
  }
  // Exporters do list child nodes as scene roots (cakeBirthday.glb does). A listed node
  // below another listed node is drawn through that one, so it is not a root of its own:
  // nothing is drawn twice.
  std::vector<char> below_listed(n, 0);
  std::vector<int> stack;
  for (int i = 0; i < n; ++i)
    if (s.nodes[i].parent < 0) stack.push_back(i);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    for (int c : s.nodes[i].children) {
      below_listed[c] = below_listed[i] || listed[i];
      stack.push_back(c);
    }
  }
  for (int r : m_.scenes[scene_index].nodes)
    if (!below_listed[r]) s.roots.push_back(r);
}

}  // namespace emaki::io::gltf_detail
