// glTF entry points: the file or bytes, the GLB container and JSON shape checked before
// tinygltf parses them, tinygltf's parse with the callbacks of gltf_files.cpp, then
// Loader::load (gltf_internal.h lists where each part of the model is read).
#include "io/gltf_loader.h"

#include <fmt/format.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/limits.h"
#include "io/gltf_internal.h"
#include "io/input_file.h"

namespace emaki::io {

namespace gltf_detail {

// In dependency order: nodes check their mesh, skin and camera indices against what is loaded,
// animations check their target nodes, and what is drawn is counted from the finished forest.
Scene Loader::load() {
  Scene s;
  s.source = path_;
  load_textures_and_materials(s);
  load_meshes(s);
  load_skins(s);
  load_cameras(s);
  load_nodes(s);
  load_animations(s);
  check_drawn_size(s);
  check_drawable(s);
  return s;
}

// ---- What is drawn ----

// Every drawn instance of a mesh is posed and rasterised separately each frame, so the drawn
// totals are bounded as well as the stored ones. The hierarchy is a forest: one visit a node.
void Loader::check_drawn_size(const Scene& s) const {
  int64_t vertices = 0, triangles = 0;
  std::vector<int> stack = s.roots;
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    const scene::Node& node = s.nodes[i];
    if (node.mesh >= 0) {
      charge(vertices, uint64_t(mesh_vertices_[node.mesh]), kMaxVertices,
             "the scene's nodes draw too many vertices, counting each instance of a mesh");
      charge(triangles, uint64_t(mesh_triangles_[node.mesh]), kMaxTriangles,
             "the scene's nodes draw too many triangles, counting each instance of a mesh");
    }
    stack.insert(stack.end(), node.children.begin(), node.children.end());
  }
}

void Loader::check_drawable(const Scene& s) const {
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

}  // namespace gltf_detail

// ---------------------------------------------------------------------------------------------
// JSON pre-scan

JsonShape scan_json_shape(std::string_view json) {
  JsonShape shape;
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character cannot end the string
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      ++shape.containers;
      shape.max_depth = std::max(shape.max_depth, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return shape;
}

namespace {

namespace fs = std::filesystem;
using scene::Scene;

// tinygltf's messages can span lines and quote whole data: uris; the CLI prints one short line.
std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return echo(s, 240);
}

// ---------------------------------------------------------------------------------------------
// GLB container: checked here, before tinygltf, which reads 8 bytes past a BIN chunk whose
// length reaches the end of the file.

std::string_view glb_json_chunk(std::string_view bytes, const std::string& name,
                                std::size_t& length) {
  auto u32 = [&](std::size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20) throw Error(name, "not a valid glTF file: truncated GLB header");
  if (u32(4) != 2)
    throw Error(name, fmt::format("not a valid glTF file: GLB version {}, expected 2", u32(4)));
  const uint64_t total = u32(8);
  if (total > bytes.size() || total < 20)
    throw Error(name, fmt::format("not a valid glTF file: the GLB header says {} bytes, the file "
                                  "has {}",
                                  total, bytes.size()));
  const uint64_t json_length = u32(12);
  const uint64_t json_end = 20 + json_length;
  if (u32(16) != 0x4E4F534A || json_length == 0 || json_end > total)
    throw Error(name, "not a valid glTF file: the GLB has no valid JSON chunk");
  if (json_end < total) {
    const uint64_t bin_length = json_end + 8 <= total ? u32(json_end) : 0;
    if (json_end + 8 > total || json_end + 8 + bin_length > total)
      throw Error(name, "not a valid glTF file: the GLB's second chunk runs past its end");
  }
  length = std::size_t(total);
  return bytes.substr(20, json_length);
}

void check_json_shape(std::string_view json, const std::string& name) {
  const JsonShape shape = scan_json_shape(json);
  if (shape.max_depth > kMaxJsonDepth)
    throw Error(name, fmt::format("not a valid glTF file: its JSON nests {} levels deep (at most "
                                  "{} allowed)",
                                  shape.max_depth, kMaxJsonDepth));
  if (shape.containers > kMaxJsonContainers)
    throw Error(name, fmt::format("not a valid glTF file: its JSON holds {} arrays and objects "
                                  "(at most {} allowed)",
                                  shape.containers, kMaxJsonContainers));
}

Scene load_bytes(std::string_view bytes, const std::string& name, const fs::path& root,
                 const std::string& base_dir, const GltfOptions& options) {
  if (bytes.size() > uint64_t(kMaxFileBytes))
    throw Error(name, fmt::format("is {} bytes; a scene file may have at most {}", bytes.size(),
                                  kMaxFileBytes));
  // Sniff the magic rather than trust the extension.
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::size_t length = bytes.size();
  check_json_shape(binary ? glb_json_chunk(bytes, name, length) : bytes, name);

  tinygltf::Model model;
  tinygltf::TinyGLTF gltf;
  gltf_detail::FileAccess files;
  files.root = root;
  files.allow_outside = options.allow_outside_paths;
  gltf.SetFsCallbacks(gltf_detail::file_callbacks(&files));
  gltf_detail::ImageAccess images;
  images.model = &model;
  gltf.SetImageLoader(&gltf_detail::keep_encoded_image, &images);
  std::string err, warn;
  const bool ok =
      binary
          ? gltf.LoadBinaryFromMemory(&model, &err, &warn,
                                      reinterpret_cast<const unsigned char*>(bytes.data()),
                                      unsigned(length), base_dir)
          : gltf.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(length), base_dir);
  // Refusals come first: tinygltf reports them only as "file not found" or a warning.
  if (!files.refused.empty()) throw Error(name, files.refused);
  if (!images.error.empty()) throw Error(name, images.error);
  if (!ok || !err.empty())
    throw Error(name,
                "not a valid glTF file: " + one_line(err.empty() ? "could not be parsed" : err));
  // Extensions the file cannot be drawn without: only those whose data we read are accepted.
  for (const std::string& ext_name : model.extensionsRequired) {
    if (ext_name != "KHR_mesh_quantization" && ext_name != "KHR_materials_unlit" &&
        ext_name != "KHR_texture_transform" && ext_name.rfind("KHR_materials_", 0) != 0)
      throw Error(name, fmt::format("requires the glTF extension {}, which is not supported",
                                    echo(ext_name)));
  }
  return gltf_detail::Loader(name, model).load();
}

fs::path canonical_folder(const fs::path& dir) {
  std::error_code ec;
  const fs::path abs = fs::absolute(dir.empty() ? fs::path(".") : dir, ec);
  const fs::path real = ec ? fs::path() : fs::weakly_canonical(abs, ec);
  return ec ? fs::path() : real;
}

}  // namespace

Scene load_gltf(const std::string& path, const GltfOptions& options) {
  if (const std::string problem = input_file_problem(path); !problem.empty())
    throw Error(path, problem);
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw Error(path, "cannot be read");
  if (size > uint64_t(kMaxFileBytes))
    throw Error(path,
                fmt::format("is {} bytes; a scene file may have at most {}", size, kMaxFileBytes));
  std::string bytes(size, '\0');
  std::ifstream in(path, std::ios::binary);
  if (!in.read(bytes.data(), std::streamsize(size))) throw Error(path, "cannot be read");
  const fs::path dir = fs::path(path).parent_path();
  return load_bytes(bytes, path, canonical_folder(dir), dir.string(), options);
}

Scene load_gltf_from_memory(std::string_view bytes, const std::string& name,
                            const std::string& base_dir, const GltfOptions& options) {
  return load_bytes(bytes, name, base_dir.empty() ? fs::path() : canonical_folder(base_dir),
                    base_dir, options);
}

}  // namespace emaki::io
