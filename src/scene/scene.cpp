#include "scene/scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <set>

#include "core/check.h"
#include "core/error.h"
#include "core/limits.h"

namespace emaki::scene {

namespace {

template <typename T>
int64_t bytes_of(const std::vector<T>& v) {
  return int64_t(v.size()) * int64_t(sizeof(T));
}

}  // namespace

int64_t primitive_bytes(const Primitive& p) {
  int64_t n = bytes_of(p.positions) + bytes_of(p.normals) + bytes_of(p.uvs) + bytes_of(p.joints) +
              bytes_of(p.weights) + bytes_of(p.indices) + bytes_of(p.rest_positions);
  for (const MorphTarget& t : p.targets) n += bytes_of(t.positions) + bytes_of(t.normals);
  return n;
}

SceneBytes scene_bytes(const Scene& scene) {
  SceneBytes b;
  std::set<const Image<float>*> seen;
  for (const Texture& t : scene.textures)
    if (t.rgba && seen.insert(t.rgba.get()).second) b.textures += int64_t(t.rgba->bytes());
  for (const Mesh& m : scene.meshes)
    for (const Primitive& p : m.primitives) b.geometry += primitive_bytes(p);
  return b;
}

int Scene::find_animation(const std::string& name) const {
  for (int i = 0; i < int(animations.size()); ++i)
    if (animations[i].name == name) return i;
  return -1;
}

// ---------------------------------------------------------------------------------------------
// Keyframe sampling

namespace {
glm::quat quat_from(const float* xyzw) {
  return glm::quat(xyzw[3], xyzw[0], xyzw[1], xyzw[2]);
}
void store(const glm::quat& q, float* xyzw) {
  xyzw[0] = q.x, xyzw[1] = q.y, xyzw[2] = q.z, xyzw[3] = q.w;
}
}  // namespace

void sample(const AnimSampler& s, float t, bool is_rotation, float* out) {
  const int n = int(s.times.size());
  const int c = s.components;
  CHECK_GT(n, 0);
  const bool cubic = s.interpolation == Interpolation::kCubicSpline;
  // Cubic-spline keys hold (in-tangent, value, out-tangent); the value sits in the middle.
  const int stride = cubic ? 3 * c : c;
  const int value_offset = cubic ? c : 0;
  auto key = [&](int i) { return s.values.data() + std::size_t(i) * stride + value_offset; };

  if (n == 1 || t <= s.times.front()) {
    std::copy_n(key(0), c, out);
    return;
  }
  if (t >= s.times.back()) {
    std::copy_n(key(n - 1), c, out);
    return;
  }
  const int i = int(std::upper_bound(s.times.begin(), s.times.end(), t) - s.times.begin()) - 1;
  const float t0 = s.times[i], t1 = s.times[i + 1];
  const float dt = t1 - t0;
  const float u = dt > 0.0f ? (t - t0) / dt : 0.0f;

  switch (s.interpolation) {
    case Interpolation::kStep:
      std::copy_n(key(i), c, out);
      return;
    case Interpolation::kLinear:
      if (is_rotation) {
        store(glm::normalize(glm::slerp(quat_from(key(i)), quat_from(key(i + 1)), u)), out);
      } else {
        for (int k = 0; k < c; ++k) out[k] = key(i)[k] + (key(i + 1)[k] - key(i)[k]) * u;
      }
      return;
    case Interpolation::kCubicSpline: {
      // glTF 2.0 Appendix C: Hermite spline with tangents scaled by the key interval.
      const float* v0 = key(i);
      const float* b0 = v0 + c;  // out-tangent of key i
      const float* v1 = key(i + 1);
      const float* a1 = v1 - c;  // in-tangent of key i+1
      const float u2 = u * u, u3 = u2 * u;
      const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
      const float h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
      for (int k = 0; k < c; ++k)
        out[k] = h00 * v0[k] + h10 * dt * b0[k] + h01 * v1[k] + h11 * dt * a1[k];
      if (is_rotation) store(glm::normalize(quat_from(out)), out);
      return;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Pose

namespace {
float channel_time(const AnimChannel& ch, float t) {
  double x = double(t) + ch.time_offset;
  if (ch.loop_length > 0.0) x -= std::floor(x / ch.loop_length) * ch.loop_length;
  return float(ch.time_base + x);
}
}  // namespace

Pose evaluate_pose(const Scene& scene, int animation, float time) {
  const int n = int(scene.nodes.size());
  Pose pose;
  pose.translation.resize(n);
  pose.rotation.resize(n);
  pose.scale.resize(n);
  pose.weights.resize(n);
  pose.world.assign(n, glm::mat4(1.0f));
  for (int i = 0; i < n; ++i) {
    const Node& node = scene.nodes[i];
    pose.translation[i] = node.translation;
    if (node.velocity != glm::vec3(0.0f)) pose.translation[i] += time * node.velocity;
    pose.rotation[i] = node.rotation;
    pose.scale[i] = node.scale;
    pose.weights[i] = node.weights;
  }
  if (animation >= 0) {
    const Animation& anim = scene.animations.at(animation);
    float buf[4];
    for (const AnimChannel& ch : anim.channels) {
      const AnimSampler& s = anim.samplers.at(ch.sampler);
      const float t = channel_time(ch, time);
      switch (ch.path) {
        case AnimPath::kTranslation:
          sample(s, t, false, buf);
          pose.translation[ch.node] = {buf[0], buf[1], buf[2]};
          break;
        case AnimPath::kRotation:
          sample(s, t, true, buf);
          pose.rotation[ch.node] = quat_from(buf);
          break;
        case AnimPath::kScale:
          sample(s, t, false, buf);
          pose.scale[ch.node] = {buf[0], buf[1], buf[2]};
          break;
        case AnimPath::kWeights: {
          std::vector<float>& w = pose.weights[ch.node];
          w.assign(s.components, 0.0f);
          sample(s, t, false, w.data());
          break;
        }
      }
    }
  }
  // Parents before children: walk down from every parentless node. The nodes form a forest (a
  // loader invariant), so each is reached once; the count guards the invariant.
  std::vector<int> stack;
  for (int i = 0; i < n; ++i)
    if (scene.nodes[i].parent < 0) stack.push_back(i);
  int visited = 0;
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    CHECK_LE(++visited, n);
    const Node& node = scene.nodes[i];
    glm::mat4 local;
    if (node.has_matrix) {
      local = node.matrix;
    } else {
      local = glm::translate(glm::mat4(1.0f), pose.translation[i]) *
              glm::mat4_cast(pose.rotation[i]) * glm::scale(glm::mat4(1.0f), pose.scale[i]);
    }
    pose.world[i] = node.parent >= 0 ? pose.world[node.parent] * local : local;
    for (int k = 0; k < 4; ++k)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(pose.world[i][k][r]))
          throw Error(scene.source,
                      fmt::format("node {} ('{}') has a non-finite world transform at {} s (its "
                                  "transforms or animation values overflow)",
                                  i, echo(node.name), time));
    for (int c : node.children) stack.push_back(c);
  }
  return pose;
}

// ---------------------------------------------------------------------------------------------
// Posed geometry

namespace {

// The matrix that carries normals: the cofactor matrix (inverse transpose up to a scale that
// the final normalisation removes), which stays defined for singular transforms.
glm::mat3 normal_matrix(const glm::mat4& m) {
  const glm::vec3 a(m[0]), b(m[1]), c(m[2]);
  return glm::mat3(glm::cross(b, c), glm::cross(c, a), glm::cross(a, b));
}

glm::vec3 safe_normalize(const glm::vec3& v) {
  const float len = glm::length(v);
  return len > 1e-20f ? v / len : glm::vec3(0.0f, 1.0f, 0.0f);
}

void smooth_normals(const std::vector<glm::vec3>& p, const std::vector<uint32_t>& idx,
                    std::vector<glm::vec3>& n) {
  n.assign(p.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
    const glm::vec3 fn = glm::cross(p[idx[t + 1]] - p[idx[t]], p[idx[t + 2]] - p[idx[t]]);
    for (int k = 0; k < 3; ++k) n[idx[t + k]] += fn;
  }
  for (auto& v : n) v = safe_normalize(v);
}

// Joint matrices of each skin at one pose, computed on first use: a file may draw many
// primitives with one skin of many joints.
class JointMatrices {
 public:
  JointMatrices(const Scene& scene, const Pose& pose)
      : scene_(scene), pose_(pose), cache_(scene.skins.size()), done_(scene.skins.size(), 0) {}
  const std::vector<glm::mat4>& of(int skin_index) {
    if (!done_[skin_index]) {
      const Skin& skin = scene_.skins[skin_index];
      std::vector<glm::mat4>& m = cache_[skin_index];
      m.resize(skin.joints.size());
      for (std::size_t j = 0; j < skin.joints.size(); ++j)
        m[j] = pose_.world[skin.joints[j]] * skin.inverse_bind[j];
      done_[skin_index] = 1;
    }
    return cache_[skin_index];
  }

 private:
  const Scene& scene_;
  const Pose& pose_;
  std::vector<std::vector<glm::mat4>> cache_;
  std::vector<char> done_;
};

void pose_primitive(const Scene& scene, const Pose& pose, JointMatrices& joints, int node_index,
                    const Primitive& prim, const std::vector<float>& morph_weights,
                    PosedPrimitive& out) {
  const Node& node = scene.nodes[node_index];
  const std::size_t nv = prim.positions.size();
  std::vector<glm::vec3> pos = prim.positions;
  std::vector<glm::vec3> nrm = prim.normals;
  for (std::size_t k = 0; k < prim.targets.size() && k < morph_weights.size(); ++k) {
    const float w = morph_weights[k];
    if (w == 0.0f) continue;
    const MorphTarget& target = prim.targets[k];
    for (std::size_t v = 0; v < target.positions.size() && v < nv; ++v)
      pos[v] += w * target.positions[v];
    for (std::size_t v = 0; v < target.normals.size() && v < nrm.size(); ++v)
      nrm[v] += w * target.normals[v];
  }
  const bool has_normals = nrm.size() == nv;
  out.world_positions.resize(nv);
  out.world_normals.resize(nv);
  const bool skinned = node.skin >= 0 && prim.joints.size() == nv && prim.weights.size() == nv;
  if (skinned) {
    // glTF: a skinned mesh ignores its own node's transform; joints carry it.
    const std::vector<glm::mat4>& joint_matrix = joints.of(node.skin);
    for (std::size_t v = 0; v < nv; ++v) {
      glm::mat4 m(0.0f);
      const glm::vec4 w = prim.weights[v];
      for (int k = 0; k < 4; ++k)
        if (w[k] != 0.0f) m += w[k] * joint_matrix.at(prim.joints[v][k]);
      out.world_positions[v] = glm::vec3(m * glm::vec4(pos[v], 1.0f));
      if (has_normals) out.world_normals[v] = safe_normalize(normal_matrix(m) * nrm[v]);
    }
  } else {
    const glm::mat4& m = pose.world[node_index];
    const glm::mat3 nm = normal_matrix(m);
    for (std::size_t v = 0; v < nv; ++v) {
      out.world_positions[v] = glm::vec3(m * glm::vec4(pos[v], 1.0f));
      if (has_normals) out.world_normals[v] = safe_normalize(nm * nrm[v]);
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    const glm::vec3& p = out.world_positions[v];
    // Written so that NaN fails too.
    if (!(std::abs(p.x) <= kMaxWorldCoordinate && std::abs(p.y) <= kMaxWorldCoordinate &&
          std::abs(p.z) <= kMaxWorldCoordinate))
      throw Error(scene.source,
                  fmt::format("node {} ('{}') poses vertex {} at ({}, {}, {}): posed positions "
                              "must be finite and within ±{:g}",
                              node_index, echo(node.name), v, p.x, p.y, p.z, kMaxWorldCoordinate));
  }
  if (!has_normals) smooth_normals(out.world_positions, prim.indices, out.world_normals);
  out.rest_positions = prim.rest_positions.empty() ? &prim.positions : &prim.rest_positions;
  out.uvs = &prim.uvs;
  out.indices = &prim.indices;
  out.material = prim.material;
}

}  // namespace

PosedScene pose_scene(const Scene& scene, int animation, float t) {
  const Pose pose = evaluate_pose(scene, animation, t);
  JointMatrices joints(scene, pose);
  PosedScene posed;
  // Depth-first over the displayed scene, children in file order, so object ids are stable.
  std::vector<int> stack(scene.roots.rbegin(), scene.roots.rend());
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const Node& node = scene.nodes[i];
    if (node.mesh >= 0) {
      const Mesh& mesh = scene.meshes[node.mesh];
      const std::vector<float>& weights = !pose.weights[i].empty() ? pose.weights[i] : mesh.weights;
      for (int p = 0; p < int(mesh.primitives.size()); ++p) {
        PosedPrimitive out;
        out.node = i;
        out.mesh = node.mesh;
        out.primitive = p;
        out.object_id = node.object_id >= 0 ? node.object_id : posed.object_count;
        pose_primitive(scene, pose, joints, i, mesh.primitives[p], weights, out);
        posed.primitives.push_back(std::move(out));
      }
      ++posed.object_count;
    }
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.push_back(*it);
  }
  return posed;
}

Bounds world_bounds(const PosedScene& posed) {
  Bounds b;
  for (const auto& p : posed.primitives)
    for (uint32_t i : *p.indices) b.add(p.world_positions[i]);
  return b;
}

Bounds rest_bounds(const PosedScene& posed) {
  Bounds b;
  for (const auto& p : posed.primitives)
    for (uint32_t i : *p.indices) b.add((*p.rest_positions)[i]);
  return b;
}

}  // namespace emaki::scene
