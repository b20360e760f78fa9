// Internals of gltf_loader.h shared by its source files (not installed, not for other modules):
//   gltf_loader.cpp     entry points, the GLB container and JSON pre-checks, what is drawn
//   gltf_files.cpp      tinygltf's callbacks: external files and encoded images
//   gltf_accessors.cpp  reading accessors, every byte range checked
//   gltf_material.cpp   materials and base-colour textures
//   gltf_mesh.cpp       meshes and their primitives
//   gltf_nodes.cpp      skins, cameras and the node forest
//   gltf_animation.cpp  animations
#pragma once

#include <tiny_gltf.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "io/gltf_loader.h"
#include "scene/scene.h"

namespace emaki::io::gltf_detail {

namespace fs = std::filesystem;
using scene::Scene;

// A double from the JSON that must become a finite float.
inline bool finite_float(double v) {
  return std::isfinite(v) && std::abs(v) <= double(FLT_MAX);
}

// ---------------------------------------------------------------------------------------------
// External files: tinygltf reads buffers and images through these callbacks, which refuse
// paths outside the scene's folder (unless allowed), non-regular files and oversized files.

struct FileAccess {
  fs::path root;  // canonical folder of the scene; empty: no external file may be read
  bool allow_outside = false;
  std::string refused;  // the first refusal, a sentence for the error line
  int64_t bytes_read = 0;

  void refuse(const std::string& why) {
    if (refused.empty()) refused = why;
  }
};

// tinygltf::FsCallbacks with a FileAccess as user data.
tinygltf::FsCallbacks file_callbacks(FileAccess* files);

// ---------------------------------------------------------------------------------------------
// Images: tinygltf hands every image's bytes to this callback while it parses. Nothing is
// decoded here: the header's size is checked against the pixel budget and the encoded bytes are
// kept, so that only base-colour textures are decoded, later, within kMaxTexturePixels.

struct ImageAccess {
  const tinygltf::Model* model = nullptr;
  std::string error;  // the first problem, a sentence for the error line

  bool fail(const std::string& why) {
    if (error.empty()) error = why;
    return false;
  }
};

// tinygltf::LoadImageDataFunction with an ImageAccess as user data.
bool keep_encoded_image(tinygltf::Image* image, const int index, std::string*, std::string*, int,
                        int, const unsigned char* bytes, int size, void* user);

// ---------------------------------------------------------------------------------------------
// tinygltf::Model -> Scene. One Loader per file: it carries the running totals that the limits
// of gltf_loader.h are charged against. Its member functions are defined by topic in the files
// listed at the top.

class Loader {
 public:
  Loader(const std::string& path, const tinygltf::Model& model) : path_(path), m_(model) {}

  [[noreturn]] void fail(const std::string& message) const { throw Error(path_, message); }

  Scene load();

 private:
  struct Span {
    const unsigned char* data = nullptr;
    std::size_t stride = 0;
  };

  // ---- Accessors (gltf_accessors.cpp) ----
  const tinygltf::Accessor& accessor(int index, const std::string& what) const;
  int components(const tinygltf::Accessor& acc, int index, const std::string& what) const;
  std::size_t values_of(const tinygltf::Accessor& acc, int comps, int index,
                        const std::string& what);
  Span locate(const tinygltf::Accessor& acc, int comps, int index, const std::string& what) const;
  std::vector<float> read_floats(int index, int expected_components, const std::string& what);
  std::vector<uint32_t> read_uints(int index, const std::string& what);
  float component(const unsigned char* p, int c, const tinygltf::Accessor& acc) const;
  template <typename V>
  std::vector<V> read_vecs(int index, const std::string& what) {
    constexpr int n = V::length();
    const std::vector<float> f = read_floats(index, n, what);
    std::vector<V> out(f.size() / n);
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < n; ++c) out[i][c] = f[i * n + c];
    return out;
  }
  void charge(int64_t& total, uint64_t n, int64_t limit, const std::string& what) const;

  // ---- Materials and textures (gltf_material.cpp) ----
  void load_textures_and_materials(Scene& s);
  int base_color_texture(Scene& s, int tex, const std::string& material);
  scene::Texture decode_texture(const tinygltf::Texture& t, int tex);

  // ---- Meshes (gltf_mesh.cpp) ----
  void load_meshes(Scene& s);
  scene::Primitive load_primitive(std::size_t mi, const tinygltf::Primitive& prim, int mode,
                                  const std::string& where);
  void read_skin_attributes(const tinygltf::Primitive& prim, const std::string& where,
                            scene::Primitive& p);
  void read_morph_targets(const tinygltf::Primitive& prim, const std::string& where,
                          scene::Primitive& p);
  std::vector<uint32_t> read_indices(const tinygltf::Primitive& prim, const std::string& where,
                                     std::size_t vertices);
  void check_count(const std::string& where, std::size_t n, std::size_t vertices,
                   const char* name) const;

  // ---- Skins, cameras and nodes (gltf_nodes.cpp) ----
  void load_skins(Scene& s);
  void load_cameras(Scene& s);
  void load_nodes(Scene& s);
  void load_node(Scene& s, int i);
  void check_no_cycles(const Scene& s) const;
  void check_skinned_joints(const Scene& s) const;
  void find_roots(Scene& s) const;

  // ---- Animations (gltf_animation.cpp) ----
  void load_animations(Scene& s);
  scene::AnimSampler load_sampler(const tinygltf::AnimationSampler& in, const std::string& what);

  // ---- What is drawn (gltf_loader.cpp) ----
  void check_drawn_size(const Scene& s) const;
  void check_drawable(const Scene& s) const;

  std::string path_;
  const tinygltf::Model& m_;
  std::vector<int> texture_map_;
  uint64_t values_read_ = 0;
  int64_t vertices_ = 0, triangles_ = 0, texture_pixels_ = 0;
  std::vector<int64_t> mesh_vertices_, mesh_triangles_;
};

}  // namespace emaki::io::gltf_detail
