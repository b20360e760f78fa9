#include "io/gltf_loader.h"

#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/error.h"

namespace emaki::io {
namespace {

namespace fs = std::filesystem;
using scene::Scene;

// tinygltf's messages can span lines; the CLI prints one.
std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

class Loader {
 public:
  Loader(const std::string& path, const tinygltf::Model& model) : path_(path), m_(model) {}

  [[noreturn]] void fail(const std::string& message) const { throw Error(path_, message); }

  // Reads an accessor into floats (normalised integers mapped to [0,1] / [-1,1]), checking
  // every byte it touches lies inside its buffer view and buffer.
  std::vector<float> read_floats(int index, int expected_components,
                                 const std::string& what) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    const int comps = tinygltf::GetNumComponentsInType(acc.type);
    if (expected_components > 0 && comps != expected_components)
      fail(fmt::format("{} (accessor {}) has {} components, expected {}", what, index, comps,
                       expected_components));
    std::vector<float> out(std::size_t(acc.count) * comps, 0.0f);
    const Span span = locate(acc, index, what);
    if (!span.data) return out;  // no buffer view: all zeros (glTF rule)
    for (std::size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = span.data + i * span.stride;
      for (int c = 0; c < comps; ++c) out[i * comps + c] = component(p, c, acc);
    }
    return out;
  }

  std::vector<uint32_t> read_uints(int index, const std::string& what) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    const int comps = tinygltf::GetNumComponentsInType(acc.type);
    std::vector<uint32_t> out(std::size_t(acc.count) * comps, 0u);
    const Span span = locate(acc, index, what);
    if (!span.data) return out;
    const int size = tinygltf::GetComponentSizeInBytes(acc.componentType);
    for (std::size_t i = 0; i < acc.count; ++i) {
      const unsigned char* p = span.data + i * span.stride;
      for (int c = 0; c < comps; ++c) {
        const unsigned char* q = p + c * size;
        switch (acc.componentType) {
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            out[i * comps + c] = *q;
            break;
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, q, 2);
            out[i * comps + c] = v;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, q, 4);
            out[i * comps + c] = v;
            break;
          }
          default:
            fail(fmt::format("{} (accessor {}) must hold unsigned integers", what, index));
        }
      }
    }
    return out;
  }

  Scene load() {
    Scene s;
    load_textures_and_materials(s);
    load_meshes(s);
    load_skins(s);
    for (const auto& c : m_.cameras) {
      scene::CameraDef def;
      def.name = c.name;
      def.perspective = c.type != "orthographic";
      if (def.perspective) {
        def.yfov = float(c.perspective.yfov);
        def.znear = float(c.perspective.znear);
      } else {
        def.xmag = float(c.orthographic.xmag);
        def.ymag = float(c.orthographic.ymag);
        def.znear = float(c.orthographic.znear);
      }
      s.cameras.push_back(def);
    }
    load_nodes(s);
    load_animations(s);
    check_drawable(s);
    return s;
  }

 private:
  struct Span {
    const unsigned char* data = nullptr;
    std::size_t stride = 0;
  };

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || index >= int(m_.accessors.size()))
      fail(fmt::format("{} refers to accessor {}, but the file has {}", what, index,
                       m_.accessors.size()));
    const tinygltf::Accessor& acc = m_.accessors[index];
    if (acc.sparse.isSparse)
      fail(fmt::format("{} (accessor {}) is sparse, which is not supported", what, index));
    return acc;
  }

  Span locate(const tinygltf::Accessor& acc, int index, const std::string& what) const {
    if (acc.bufferView < 0) return {};
    if (acc.bufferView >= int(m_.bufferViews.size()))
      fail(fmt::format("{} (accessor {}) refers to buffer view {}, but the file has {}", what,
                       index, acc.bufferView, m_.bufferViews.size()));
    const tinygltf::BufferView& view = m_.bufferViews[acc.bufferView];
    if (view.buffer < 0 || view.buffer >= int(m_.buffers.size()))
      fail(fmt::format("buffer view {} refers to buffer {}, but the file has {}", acc.bufferView,
                       view.buffer, m_.buffers.size()));
    const tinygltf::Buffer& buffer = m_.buffers[view.buffer];
    const int comps = tinygltf::GetNumComponentsInType(acc.type);
    const int csize = tinygltf::GetComponentSizeInBytes(acc.componentType);
    if (comps <= 0 || csize <= 0)
      fail(fmt::format("{} (accessor {}) has an invalid type", what, index));
    const std::size_t elem = std::size_t(comps) * csize;
    const std::size_t stride = view.byteStride > 0 ? view.byteStride : elem;
    const std::size_t need = acc.count == 0 ? 0 : acc.byteOffset + stride * (acc.count - 1) + elem;
    if (need > view.byteLength)
      fail(
          fmt::format("{} (accessor {}) is out of range: it needs {} bytes of buffer view {}, "
                      "which has {}",
                      what, index, need, acc.bufferView, view.byteLength));
    if (view.byteOffset + view.byteLength > buffer.data.size())
      fail(fmt::format(
          "buffer view {} is out of range: it ends at byte {} of buffer {}, which "
          "has {}",
          acc.bufferView, view.byteOffset + view.byteLength, view.buffer, buffer.data.size()));
    return {buffer.data.data() + view.byteOffset + acc.byteOffset, stride};
  }

  float component(const unsigned char* p, int c, const tinygltf::Accessor& acc) const {
    switch (acc.componentType) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p + 4 * c, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        const float v = p[c];
        return acc.normalized ? v / 255.0f : v;
      }
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const float v = float(int8_t(p[c]));
        return acc.normalized ? std::max(v / 127.0f, -1.0f) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return acc.normalized ? v / 65535.0f : float(v);
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return acc.normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p + 4 * c, 4);
        return float(v);
      }
      default:
        fail(fmt::format("unsupported accessor component type {}", acc.componentType));
    }
  }

  template <typename V>
  std::vector<V> read_vecs(int index, const std::string& what) const {
    constexpr int n = V::length();
    const std::vector<float> f = read_floats(index, n, what);
    std::vector<V> out(f.size() / n);
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < n; ++c) out[i][c] = f[i * n + c];
    return out;
  }

  void load_textures_and_materials(Scene& s) {
    texture_map_.assign(m_.textures.size(), -1);
    for (const auto& mat : m_.materials) {
      scene::Material out;
      out.name = mat.name;
      const auto& f = mat.pbrMetallicRoughness.baseColorFactor;
      if (f.size() == 4) out.base_color = glm::vec4(f[0], f[1], f[2], f[3]);
      const int tex = mat.pbrMetallicRoughness.baseColorTexture.index;
      if (tex >= 0) {
        out.base_color_texture = base_color_texture(s, tex, mat.name);
        out.texcoord = mat.pbrMetallicRoughness.baseColorTexture.texCoord;
      }
      s.materials.push_back(std::move(out));
    }
  }

  int base_color_texture(Scene& s, int tex, const std::string& material) {
    if (tex >= int(m_.textures.size()))
      fail(fmt::format("material '{}' refers to texture {}, but the file has {}", material, tex,
                       m_.textures.size()));
    if (texture_map_[tex] >= 0) return texture_map_[tex];
    const tinygltf::Texture& t = m_.textures[tex];
    if (t.source < 0 || t.source >= int(m_.images.size()))
      fail(fmt::format("texture {} refers to image {}, but the file has {}", tex, t.source,
                       m_.images.size()));
    const tinygltf::Image& img = m_.images[t.source];
    const std::string name = img.uri.empty() ? fmt::format("image {}", t.source) : img.uri;
    if (img.width <= 0 || img.height <= 0 || img.component <= 0 || img.image.empty())
      fail(fmt::format("texture {} ({}) did not decode", tex, name));
    const int comps = img.component;
    const int bytes = img.bits == 16 ? 2 : 1;
    if (img.image.size() < std::size_t(img.width) * img.height * comps * bytes)
      fail(fmt::format("texture {} ({}) did not decode: too little pixel data", tex, name));
    scene::Texture out;
    out.rgba.reset(img.width, img.height, 4);
    for (int y = 0; y < img.height; ++y) {
      float* row = out.rgba.row(y);
      for (int x = 0; x < img.width; ++x) {
        float v[4] = {0, 0, 0, 1};
        for (int c = 0; c < comps && c < 4; ++c) {
          const std::size_t i = (std::size_t(y) * img.width + x) * comps + c;
          if (bytes == 2) {
            uint16_t u;
            std::memcpy(&u, img.image.data() + 2 * i, 2);
            v[c] = u / 65535.0f;
          } else {
            v[c] = img.image[i] / 255.0f;
          }
        }
        if (comps < 3) v[1] = v[2] = v[0];  // grey (+ alpha)
        if (comps == 2) v[3] = img.image[(std::size_t(y) * img.width + x) * comps + 1] / 255.0f;
        for (int c = 0; c < 3; ++c) row[4 * x + c] = srgb_to_linear(v[c]);
        row[4 * x + 3] = v[3];
      }
    }
    if (t.sampler >= 0 && t.sampler < int(m_.samplers.size())) {
      auto wrap = [](int mode) {
        switch (mode) {
          case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
            return scene::Texture::Wrap::kClamp;
          case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
            return scene::Texture::Wrap::kMirror;
          default:
            return scene::Texture::Wrap::kRepeat;
        }
      };
      out.wrap_s = wrap(m_.samplers[t.sampler].wrapS);
      out.wrap_t = wrap(m_.samplers[t.sampler].wrapT);
    }
    s.textures.push_back(std::move(out));
    texture_map_[tex] = int(s.textures.size()) - 1;
    return texture_map_[tex];
  }

  void load_meshes(Scene& s) {
    for (int mi = 0; mi < int(m_.meshes.size()); ++mi) {
      const tinygltf::Mesh& mesh = m_.meshes[mi];
      scene::Mesh out;
      out.name = mesh.name;
      for (double w : mesh.weights) out.weights.push_back(float(w));
      for (int pi = 0; pi < int(mesh.primitives.size()); ++pi) {
        const tinygltf::Primitive& prim = mesh.primitives[pi];
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN)
          continue;  // points and lines draw nothing in a guide pass
        const std::string where = fmt::format("mesh {} ('{}') primitive {}", mi, mesh.name, pi);
        auto attr = [&](const char* name) {
          auto it = prim.attributes.find(name);
          return it == prim.attributes.end() ? -1 : it->second;
        };
        if (attr("POSITION") < 0) fail(where + " has no POSITION attribute");
        scene::Primitive p;
        p.positions = read_vecs<glm::vec3>(attr("POSITION"), where + " POSITION");
        const std::size_t nv = p.positions.size();
        auto check_count = [&](std::size_t n, const char* name) {
          if (n != nv)
            fail(fmt::format("{} {} has {} elements, POSITION has {}", where, name, n, nv));
        };
        if (attr("NORMAL") >= 0) {
          p.normals = read_vecs<glm::vec3>(attr("NORMAL"), where + " NORMAL");
          check_count(p.normals.size(), "NORMAL");
        }
        if (attr("TEXCOORD_0") >= 0) {
          p.uvs = read_vecs<glm::vec2>(attr("TEXCOORD_0"), where + " TEXCOORD_0");
          check_count(p.uvs.size(), "TEXCOORD_0");
        }
        if (attr("JOINTS_0") >= 0 && attr("WEIGHTS_0") >= 0) {
          const std::vector<uint32_t> j = read_uints(attr("JOINTS_0"), where + " JOINTS_0");
          check_count(j.size() / 4, "JOINTS_0");
          p.weights = read_vecs<glm::vec4>(attr("WEIGHTS_0"), where + " WEIGHTS_0");
          check_count(p.weights.size(), "WEIGHTS_0");
          p.joints.resize(nv);
          for (std::size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 4; ++c) p.joints[v][c] = uint16_t(j[4 * v + c]);
        }
        for (int ti = 0; ti < int(prim.targets.size()); ++ti) {
          scene::MorphTarget target;
          for (const auto& [name, index] : prim.targets[ti]) {
            const std::string what = fmt::format("{} morph target {} {}", where, ti, name);
            if (name == "POSITION") {
              target.positions = read_vecs<glm::vec3>(index, what);
              check_count(target.positions.size(), "morph POSITION");
            } else if (name == "NORMAL") {
              target.normals = read_vecs<glm::vec3>(index, what);
              check_count(target.normals.size(), "morph NORMAL");
            }
          }
          p.targets.push_back(std::move(target));
        }
        std::vector<uint32_t> idx;
        if (prim.indices >= 0) {
          idx = read_uints(prim.indices, where + " indices");
        } else {
          idx.resize(nv);
          for (std::size_t i = 0; i < nv; ++i) idx[i] = uint32_t(i);
        }
        for (uint32_t i : idx)
          if (i >= nv) fail(fmt::format("{} has index {} but only {} vertices", where, i, nv));
        p.indices = triangles(idx, mode);
        if (prim.material >= int(m_.materials.size()))
          fail(fmt::format("{} refers to material {}, but the file has {}", where, prim.material,
                           m_.materials.size()));
        p.material = prim.material;
        out.primitives.push_back(std::move(p));
      }
      s.meshes.push_back(std::move(out));
    }
  }

  static std::vector<uint32_t> triangles(const std::vector<uint32_t>& idx, int mode) {
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      std::vector<uint32_t> out(idx.begin(), idx.begin() + idx.size() / 3 * 3);
      return out;
    }
    std::vector<uint32_t> out;
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

  void load_skins(Scene& s) {
    for (int si = 0; si < int(m_.skins.size()); ++si) {
      const tinygltf::Skin& skin = m_.skins[si];
      scene::Skin out;
      out.name = skin.name;
      for (int j : skin.joints) {
        if (j < 0 || j >= int(m_.nodes.size()))
          fail(fmt::format("skin {} refers to node {}, but the file has {}", si, j,
                           m_.nodes.size()));
        out.joints.push_back(j);
      }
      if (skin.inverseBindMatrices >= 0) {
        const std::vector<float> f = read_floats(skin.inverseBindMatrices, 16,
                                                 fmt::format("skin {} inverseBindMatrices", si));
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

  void load_nodes(Scene& s) {
    const int n = int(m_.nodes.size());
    s.nodes.resize(n);
    for (int i = 0; i < n; ++i) {
      const tinygltf::Node& in = m_.nodes[i];
      scene::Node& node = s.nodes[i];
      node.name = in.name;
      if (in.translation.size() == 3)
        node.translation = glm::vec3(in.translation[0], in.translation[1], in.translation[2]);
      if (in.rotation.size() == 4)
        node.rotation = glm::quat(float(in.rotation[3]), float(in.rotation[0]),
                                  float(in.rotation[1]), float(in.rotation[2]));
      if (in.scale.size() == 3) node.scale = glm::vec3(in.scale[0], in.scale[1], in.scale[2]);
      if (in.matrix.size() == 16) {
        node.has_matrix = true;
        for (int k = 0; k < 16; ++k) node.matrix[k / 4][k % 4] = float(in.matrix[k]);
      }
      auto check_ref = [&](int ref, std::size_t count, const char* what) {
        if (ref >= int(count))
          fail(fmt::format("node {} refers to {} {}, but the file has {}", i, what, ref, count));
      };
      check_ref(in.mesh, s.meshes.size(), "mesh");
      check_ref(in.skin, s.skins.size(), "skin");
      check_ref(in.camera, s.cameras.size(), "camera");
      node.mesh = in.mesh;
      node.skin = in.skin;
      node.camera = in.camera;
      for (double w : in.weights) node.weights.push_back(float(w));
      for (int c : in.children) {
        if (c < 0 || c >= n || s.nodes[c].parent >= 0 || c == i)
          fail(fmt::format("node {} has an invalid child {}", i, c));
        node.children.push_back(c);
        s.nodes[c].parent = i;
      }
    }
    // Joint indices must stay inside the skin the mesh is drawn with.
    for (int i = 0; i < n; ++i) {
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
    const int scene_index = m_.defaultScene >= 0 ? m_.defaultScene : 0;
    if (scene_index < int(m_.scenes.size())) {
      for (int r : m_.scenes[scene_index].nodes) {
        if (r < 0 || r >= n) fail(fmt::format("scene {} refers to node {}", scene_index, r));
        s.roots.push_back(r);
      }
    } else {
      for (int i = 0; i < n; ++i)
        if (s.nodes[i].parent < 0) s.roots.push_back(i);
    }
  }

  void load_animations(Scene& s) {
    for (int ai = 0; ai < int(m_.animations.size()); ++ai) {
      const tinygltf::Animation& anim = m_.animations[ai];
      scene::Animation out;
      out.name = anim.name.empty() ? fmt::format("animation{}", ai) : anim.name;
      out.start = 1e30f;
      out.end = -1e30f;
      std::vector<int> sampler_components(anim.samplers.size(), 0);
      for (const auto& ch : anim.channels) {
        if (ch.sampler < 0 || ch.sampler >= int(anim.samplers.size()))
          fail(fmt::format("animation '{}' channel refers to sampler {}", out.name, ch.sampler));
        if (ch.target_node < 0 || ch.target_node >= int(m_.nodes.size()))
          fail(fmt::format("animation '{}' channel targets node {}", out.name, ch.target_node));
      }
      for (int si = 0; si < int(anim.samplers.size()); ++si) {
        const tinygltf::AnimationSampler& in = anim.samplers[si];
        const std::string what = fmt::format("animation '{}' sampler {}", out.name, si);
        scene::AnimSampler smp;
        smp.times = read_floats(in.input, 1, what + " input");
        if (smp.times.empty()) fail(what + " has no keyframes");
        for (std::size_t k = 1; k < smp.times.size(); ++k)
          if (!(smp.times[k] >= smp.times[k - 1]))
            fail(what + " has keyframe times that are not increasing");
        smp.values = read_floats(in.output, 0, what + " output");
        smp.interpolation = in.interpolation == "STEP"          ? scene::Interpolation::kStep
                            : in.interpolation == "CUBICSPLINE" ? scene::Interpolation::kCubicSpline
                                                                : scene::Interpolation::kLinear;
        const std::size_t keys =
            smp.times.size() * (smp.interpolation == scene::Interpolation::kCubicSpline ? 3 : 1);
        if (smp.values.size() % keys != 0 || smp.values.empty())
          fail(fmt::format("{} output has {} values for {} keys", what, smp.values.size(), keys));
        smp.components = int(smp.values.size() / keys);
        out.start = std::min(out.start, smp.times.front());
        out.end = std::max(out.end, smp.times.back());
        out.samplers.push_back(std::move(smp));
      }
      for (const auto& ch : anim.channels) {
        scene::AnimChannel c;
        c.node = ch.target_node;
        c.sampler = ch.sampler;
        int need = 3;
        if (ch.target_path == "translation") {
          c.path = scene::AnimPath::kTranslation;
        } else if (ch.target_path == "rotation") {
          c.path = scene::AnimPath::kRotation;
          need = 4;
        } else if (ch.target_path == "scale") {
          c.path = scene::AnimPath::kScale;
        } else if (ch.target_path == "weights") {
          c.path = scene::AnimPath::kWeights;
          need = -1;
        } else {
          continue;  // extension paths (KHR_animation_pointer) are not ours
        }
        const int comps = out.samplers[ch.sampler].components;
        if (need > 0 && comps != need)
          fail(fmt::format("animation '{}' {} channel has {} components per key, expected {}",
                           out.name, ch.target_path, comps, need));
        if (s.nodes[c.node].has_matrix)
          fail(fmt::format("animation '{}' animates node {}, which is given by a matrix", out.name,
                           c.node));
        out.channels.push_back(c);
      }
      if (out.samplers.empty()) out.start = out.end = 0.0f;
      s.animations.push_back(std::move(out));
    }
  }

  void check_drawable(const Scene& s) const {
    std::vector<int> stack = s.roots;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      const scene::Node& node = s.nodes[i];
      if (node.mesh >= 0)
        for (const auto& p : s.meshes[node.mesh].primitives)
          if (!p.indices.empty()) return;
      stack.insert(stack.end(), node.children.begin(), node.children.end());
    }
    fail("empty scene: no triangle mesh to draw");
  }

  std::string path_;
  const tinygltf::Model& m_;
  std::vector<int> texture_map_;
};

}  // namespace

Scene load_gltf(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw Error(path, "no such file");
  tinygltf::TinyGLTF gltf;
  tinygltf::Model model;
  std::string err, warn;
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  // Sniff the magic rather than trust the extension.
  bool binary = ext == ".glb";
  if (FILE* f = std::fopen(path.c_str(), "rb")) {
    char magic[4] = {};
    binary = std::fread(magic, 1, 4, f) == 4 && std::memcmp(magic, "glTF", 4) == 0;
    std::fclose(f);
  }
  const bool ok = binary ? gltf.LoadBinaryFromFile(&model, &err, &warn, path)
                         : gltf.LoadASCIIFromFile(&model, &err, &warn, path);
  if (!ok || !err.empty()) {
    std::string message = one_line(err.empty() ? "could not be parsed" : err);
    throw Error(path, "not a valid glTF file: " + message);
  }
  // Extensions the file cannot be drawn without: only those whose data we read are accepted.
  for (const std::string& ext_name : model.extensionsRequired) {
    if (ext_name != "KHR_mesh_quantization" && ext_name != "KHR_materials_unlit" &&
        ext_name != "KHR_texture_transform" && ext_name.rfind("KHR_materials_", 0) != 0)
      throw Error(path,
                  fmt::format("requires the glTF extension {}, which is not supported", ext_name));
  }
  return Loader(path, model).load();
}

}  // namespace emaki::io
