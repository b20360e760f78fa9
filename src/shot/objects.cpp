#include "shot/objects.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "io/gltf_loader.h"
#include "scene/assembly.h"
#include "store/output_store.h"

namespace emaki::shot {

namespace {

// A scene file read once: its bytes parsed, and digested for the manifests (file_digest). A file
// that cannot be read whole is left to load_gltf, which words the error.
scene::Scene read_scene(const std::string& path) {
  if (const std::optional<std::string> bytes =
          io::read_input_file(path, std::size_t(io::kMaxFileBytes))) {
    const std::string dir = std::filesystem::path(path).parent_path().string();
    return io::load_gltf_from_memory(*bytes, path, dir.empty() ? "." : dir);
  }
  return io::load_gltf(path);
}

std::string key_of(std::size_t i, const char* key) {
  return fmt::format("source.objects[{}].{}", i, key);
}

// What a placement of `asset` adds to the assembled scene (scene::assemble): a copy of every
// mesh, another for each further node that draws one, and rest positions for what is drawn; and
// what it draws (a mesh drawn by two nodes counts twice, as the loader counts them).
SceneCost placement_cost(const scene::Scene& asset) {
  SceneCost c;
  std::vector<int64_t> mesh_bytes;
  for (const scene::Mesh& m : asset.meshes) {
    int64_t b = 0;
    for (const scene::Primitive& p : m.primitives) b += scene::primitive_bytes(p);
    mesh_bytes.push_back(b);
    c.bytes += b;
  }
  std::vector<char> drawn(asset.meshes.size(), 0);
  std::vector<int> stack = asset.roots;
  while (!stack.empty()) {
    const scene::Node& node = asset.nodes[stack.back()];
    stack.pop_back();
    if (node.mesh >= 0) {
      if (drawn[node.mesh]) c.bytes += mesh_bytes[node.mesh];
      drawn[node.mesh] = 1;
      for (const scene::Primitive& p : asset.meshes[node.mesh].primitives) {
        c.drawn_vertices += int64_t(p.positions.size());
        c.drawn_triangles += int64_t(p.indices.size() / 3);
        c.bytes += int64_t(p.positions.size() * sizeof(glm::vec3));  // rest positions
      }
    }
    stack.insert(stack.end(), node.children.begin(), node.children.end());
  }
  return c;
}

std::string megabytes(int64_t bytes) {
  return fmt::format("{:.0f} MB", double(bytes) / 1e6);
}

void check_budget(int64_t bytes, int64_t budget, const std::string& key, const char* what) {
  if (bytes > budget)
    throw Error(key, fmt::format("{} {} of textures and geometry; a shot's scene holds at most {}",
                                 what, megabytes(bytes), megabytes(budget)));
}

// A file's identity on disk: its device and inode.
std::pair<uint64_t, uint64_t> file_identity(const std::string& path, const std::string& key) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw Error(key, fmt::format("cannot open '{}' ({})", echo_path(path), std::strerror(errno)));
  return {uint64_t(st.st_dev), uint64_t(st.st_ino)};
}

// The object's clip (-1: none in the file), checked as the renderer checks a scene's: the start
// inside the clip and, unless it loops, every frame of the shot too.
int find_clip(const scene::Scene& asset, const pipeline::SceneObject& o, std::size_t i,
              const pipeline::Source& s) {
  if (o.clip.empty() && asset.animations.empty()) return -1;
  const int clip = o.clip.empty() ? 0 : asset.find_animation(o.clip);
  if (clip < 0) {
    std::string names;
    for (std::size_t k = 0; k < asset.animations.size() && k < 16; ++k)
      names += (k ? ", '" : "'") + echo(asset.animations[k].name, 40) + "'";
    throw Error(key_of(i, "clip"), fmt::format("no clip '{}' in '{}' (clips: {})", echo(o.clip),
                                               echo_path(o.scene), names.empty() ? "none" : names));
  }
  const scene::Animation& a = asset.animations[clip];
  const double length = double(a.end) - a.start;
  if (o.start > length)
    throw Error(key_of(i, "start"), fmt::format("{} s is outside clip '{}' ({:.3f} s long)",
                                                o.start, echo(a.name), length));
  const double last = o.start + s.last_frame / double(s.fps);
  if (!o.loop && last > length + 1e-3 / s.fps)
    throw Error(key_of(i, "loop"),
                fmt::format("frame {} is at {:.3f} s of clip '{}', past its end ({:.3f} s long): "
                            "loop it or start it earlier",
                            s.last_frame, last, echo(a.name), length));
  return clip;
}

}  // namespace

scene::Scene load_objects(const pipeline::Source& s, SceneCost* cost, int64_t budget) {
  std::map<std::pair<uint64_t, uint64_t>, std::unique_ptr<scene::Scene>> assets;
  std::vector<scene::Placement> placements;
  SceneCost total;
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const pipeline::SceneObject& o = s.objects[i];
    const std::string key = key_of(i, "scene");
    std::unique_ptr<scene::Scene>& asset = assets[file_identity(o.scene, key)];
    if (!asset) {
      try {
        asset = std::make_unique<scene::Scene>(read_scene(o.scene));
      } catch (const Error& e) {
        throw Error(key, e.what());
      }
      total.bytes += scene::scene_bytes(*asset).total();
      check_budget(total.bytes, budget, key, "the objects' files so far hold");
    }
    const SceneCost placed = placement_cost(*asset);
    total.drawn_vertices += placed.drawn_vertices;
    total.drawn_triangles += placed.drawn_triangles;
    if (total.drawn_vertices > io::kMaxVertices)
      throw Error(key, fmt::format("the objects so far draw {} vertices; a shot draws at most {}",
                                   total.drawn_vertices, io::kMaxVertices));
    total.bytes += placed.bytes;
    check_budget(total.bytes, budget, key, "with this object, the scene would hold");
    scene::Placement p;
    p.asset = asset.get();
    p.translate = o.translate;
    p.rotate_deg = o.rotate_deg;
    p.scale = o.scale;
    p.velocity = o.velocity;
    p.animation = find_clip(*asset, o, i, s);
    p.start = o.start;
    p.loop = o.loop;
    // The pass holds the id + 2 (render/passes.h: 0 background, 1 ground).
    p.object_id = o.id - 2;
    placements.push_back(p);
  }
  scene::Scene out = scene::assemble(placements);
  out.source = "source.objects";
  if (cost) *cost = total;
  return out;
}

scene::Scene load_scene(const pipeline::Source& s, SceneCost* cost) {
  if (!s.objects.empty()) return load_objects(s, cost);
  scene::Scene out = read_scene(s.scene_path);
  SceneCost c = placement_cost(out);
  c.bytes = scene::scene_bytes(out).total();
  check_budget(c.bytes, kMaxSceneBytes, "source.scene", "the scene holds");
  if (cost) *cost = c;
  return out;
}

}  // namespace emaki::shot
