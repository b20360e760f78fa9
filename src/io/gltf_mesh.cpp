// Meshes and their primitives (Loader members, see gltf_internal.h). Vertex and triangle counts
// are charged per file here and remembered per mesh, for check_drawn_size to charge again per
// drawn instance.
#include <fmt/format.h>

#include <algorithm>

#include "core/limits.h"
#include "io/gltf_internal.h"

namespace emaki::io::gltf_detail {

namespace {

// The accessor index of a primitive's attribute, -1 if it has none.
int attribute(const tinygltf::Primitive& prim, const char* name) {
  auto it = prim.attributes.find(name);
  return it == prim.attributes.end() ? -1 : it->second;
}

// Triangle lists from the indices of a triangle list, strip or fan (strips alternate their
// winding so that every triangle keeps the strip's facing).
std::vector<uint32_t> triangles(const std::vector<uint32_t>& idx, int mode) {
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    std::vector<uint32_t> out(idx.begin(), idx.begin() + idx.size() / 3 * 3);
    return out;
  }
  std::vector<uint32_t> out;
  if (idx.size() >= 3) out.reserve(3 * (idx.size() - 2));
  for (std::size_t i = 2; i < idx.size(); ++i) {
    if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      out.insert(out.end(), {idx[0], idx[i - 1], idx[i]});
    } else if (i % 2 == 0) {
      out.insert(out.end(), {idx[i - 2], idx[i - 1], idx[i]});
    } else {
      out.insert(out.end(), {idx[i - 1], idx[i - 2], idx[i]});
    }
  }
  return out;
}

}  // namespace

void Loader::load_meshes(Scene& s) {
  mesh_vertices_.assign(m_.meshes.size(), 0);
  mesh_triangles_.assign(m_.meshes.size(), 0);
  for (std::size_t mi = 0; mi < m_.meshes.size(); ++mi) {
    const tinygltf::Mesh& mesh = m_.meshes[mi];
    scene::Mesh out;
    out.name = mesh.name;
    for (double w : mesh.weights) {
      if (!finite_float(w))
        fail(fmt::format("mesh {} ('{}') has a non-finite morph weight", mi, echo(mesh.name)));
      out.weights.push_back(float(w));
    }
    for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const tinygltf::Primitive& prim = mesh.primitives[pi];
      const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN)
        continue;  // points and lines draw nothing in a guide pass
      const std::string where = fmt::format("mesh {} ('{}') primitive {}", mi, echo(mesh.name), pi);
      out.primitives.push_back(load_primitive(mi, prim, mode, where));
    }
    s.meshes.push_back(std::move(out));
  }
}

// One triangle primitive of mesh `mi`; `where` names it in errors.
scene::Primitive Loader::load_primitive(std::size_t mi, const tinygltf::Primitive& prim, int mode,
                                        const std::string& where) {
  if (attribute(prim, "POSITION") < 0) fail(where + " has no POSITION attribute");
  scene::Primitive p;
  p.positions = read_vecs<glm::vec3>(attribute(prim, "POSITION"), where + " POSITION");
  const std::size_t nv = p.positions.size();
  charge(vertices_, nv, kMaxVertices, where + " takes the file past its vertex limit");
  mesh_vertices_[mi] += int64_t(nv);
  if (attribute(prim, "NORMAL") >= 0) {
    p.normals = read_vecs<glm::vec3>(attribute(prim, "NORMAL"), where + " NORMAL");
    check_count(where, p.normals.size(), nv, "NORMAL");
  }
  if (attribute(prim, "TEXCOORD_0") >= 0) {
    p.uvs = read_vecs<glm::vec2>(attribute(prim, "TEXCOORD_0"), where + " TEXCOORD_0");
    check_count(where, p.uvs.size(), nv, "TEXCOORD_0");
  }
  read_skin_attributes(prim, where, p);
  read_morph_targets(prim, where, p);
  const std::vector<uint32_t> idx = read_indices(prim, where, nv);
  const std::size_t tris =
      mode == TINYGLTF_MODE_TRIANGLES ? idx.size() / 3 : std::max<std::size_t>(idx.size(), 2) - 2;
  charge(triangles_, tris, kMaxTriangles, where + " takes the file past its triangle limit");
  mesh_triangles_[mi] += int64_t(tris);
  p.indices = triangles(idx, mode);
  if (prim.material >= 0 && std::size_t(prim.material) >= m_.materials.size())
    fail(fmt::format("{} refers to material {}, but the file has {}", where, prim.material,
                     m_.materials.size()));
  p.material = prim.material < 0 ? -1 : prim.material;
  return p;
}

// JOINTS_0 and WEIGHTS_0, read only as a pair (one without the other cannot be skinned).
void Loader::read_skin_attributes(const tinygltf::Primitive& prim, const std::string& where,
                                  scene::Primitive& p) {
  if (attribute(prim, "JOINTS_0") < 0 || attribute(prim, "WEIGHTS_0") < 0) return;
  const std::size_t nv = p.positions.size();
  const std::vector<uint32_t> j = read_uints(attribute(prim, "JOINTS_0"), where + " JOINTS_0");
  if (j.size() != nv * 4)
    fail(fmt::format("{} JOINTS_0 has {} values, expected 4 for each of {} vertices", where,
                     j.size(), nv));
  p.weights = read_vecs<glm::vec4>(attribute(prim, "WEIGHTS_0"), where + " WEIGHTS_0");
  check_count(where, p.weights.size(), nv, "WEIGHTS_0");
  p.joints.resize(nv);
  for (std::size_t v = 0; v < nv; ++v)
    for (int c = 0; c < 4; ++c) {
      if (j[4 * v + c] >= uint32_t(kMaxSkinJoints))
        fail(fmt::format("{} JOINTS_0 holds joint {}, more than a skin can have", where,
                         j[4 * v + c]));
      p.joints[v][c] = uint16_t(j[4 * v + c]);
    }
}

// Morph targets' POSITION and NORMAL displacements (other target attributes are not drawn).
void Loader::read_morph_targets(const tinygltf::Primitive& prim, const std::string& where,
                                scene::Primitive& p) {
  if (prim.targets.size() > std::size_t(kMaxMorphTargets))
    fail(fmt::format("{} has {} morph targets (at most {})", where, prim.targets.size(),
                     kMaxMorphTargets));
  const std::size_t nv = p.positions.size();
  for (std::size_t ti = 0; ti < prim.targets.size(); ++ti) {
    scene::MorphTarget target;
    for (const auto& [name, index] : prim.targets[ti]) {
      const std::string what = fmt::format("{} morph target {} {}", where, ti, echo(name));
      if (name == "POSITION") {
        target.positions = read_vecs<glm::vec3>(index, what);
        check_count(where, target.positions.size(), nv, "morph POSITION");
      } else if (name == "NORMAL") {
        target.normals = read_vecs<glm::vec3>(index, what);
        check_count(where, target.normals.size(), nv, "morph NORMAL");
      }
    }
    p.targets.push_back(std::move(target));
  }
}

// The primitive's indices (0, 1, 2, ... when it has none), each checked against its vertices.
std::vector<uint32_t> Loader::read_indices(const tinygltf::Primitive& prim,
                                           const std::string& where, std::size_t vertices) {
  std::vector<uint32_t> idx;
  if (prim.indices >= 0) {
    idx = read_uints(prim.indices, where + " indices");
  } else {
    idx.resize(vertices);
    for (std::size_t i = 0; i < vertices; ++i) idx[i] = uint32_t(i);
  }
  for (uint32_t i : idx)
    if (i >= vertices)
      fail(fmt::format("{} has index {} but only {} vertices", where, i, vertices));
  return idx;
}

// Every attribute of a primitive has one element per vertex.
void Loader::check_count(const std::string& where, std::size_t n, std::size_t vertices,
                         const char* name) const {
  if (n != vertices)
    fail(fmt::format("{} {} has {} elements, POSITION has {}", where, name, n, vertices));
}

}  // namespace emaki::io::gltf_detail
