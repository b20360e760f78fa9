#include "shot/objects.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <memory>

#include "core/error.h"
#include "core/limits.h"
#include "io/gltf_loader.h"
#include "scene/assembly.h"

namespace emaki::shot {

namespace {

std::string key_of(std::size_t i, const char* key) {
  return fmt::format("source.objects[{}].{}", i, key);
}

// Vertices the asset draws (a mesh drawn by two nodes counts twice), as the loader counts them.
int64_t drawn_vertices(const scene::Scene& s) {
  int64_t n = 0;
  std::vector<int> stack = s.roots;
  while (!stack.empty()) {
    const scene::Node& node = s.nodes[stack.back()];
    stack.pop_back();
    if (node.mesh >= 0)
      for (const scene::Primitive& p : s.meshes[node.mesh].primitives) n += p.positions.size();
    stack.insert(stack.end(), node.children.begin(), node.children.end());
  }
  return n;
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

scene::Scene load_objects(const pipeline::Source& s) {
  std::map<std::string, std::unique_ptr<scene::Scene>> assets;
  std::vector<scene::Placement> placements;
  int64_t vertices = 0;
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    const pipeline::SceneObject& o = s.objects[i];
    std::unique_ptr<scene::Scene>& asset = assets[o.scene];
    try {
      if (!asset) asset = std::make_unique<scene::Scene>(io::load_gltf(o.scene));
    } catch (const Error& e) {
      throw Error(key_of(i, "scene"), e.what());
    }
    vertices += drawn_vertices(*asset);
    if (vertices > io::kMaxVertices)
      throw Error(key_of(i, "scene"),
                  fmt::format("the objects so far draw {} vertices; a shot draws at most {}",
                              vertices, io::kMaxVertices));
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
  return out;
}

}  // namespace emaki::shot
