// source.objects: the assets of an assembled scene, as the shot file places them. Their files
// are opened with the shot's inputs (shot/inputs.cpp), not here.
#include <fmt/format.h>

#include <cmath>

#include "scene/assembly.h"
#include "shot/parser_sections.h"

namespace emaki::shot {

namespace {

// `scale`: one number for all three axes, or [x, y, z]; each within the schema's range.
glm::vec3 parse_scale(const Reader& r, glm::vec3 fallback) {
  const toml::node* n = r.node("scale");
  if (!n) return fallback;
  if (!n->is_array()) return glm::vec3(r.real("scale", fallback.x));
  const std::vector<float> v = r.numbers("scale", 3);
  const KeySpec* k = find_key("source.objects[N].scale");
  for (float x : v)
    if (!(x >= k->lo && x <= k->hi))
      throw Error(r.key_path("scale"),
                  fmt::format("each factor must be in [{}, {}], got {}", k->lo, k->hi, x));
  return {v[0], v[1], v[2]};
}

pipeline::SceneObject parse_object(const Reader& r, const PathContext& ctx, int default_id) {
  pipeline::SceneObject o;
  o.scene = ctx.input_file(r, "scene", true);
  o.translate = r.vec3("translate", o.translate);
  o.rotate_deg = r.vec3("rotate", o.rotate_deg);
  o.scale = parse_scale(r, o.scale);
  o.velocity = r.vec3("velocity", o.velocity);
  o.clip = r.string("clip", o.clip);
  o.start = r.real("start", o.start);
  o.loop = r.boolean("loop", o.loop);
  o.id = r.integer("id", default_id);
  const double most = find_key("source.objects[N].id")->hi;
  if (o.id > most)
    throw Error(r.key_path("id"), fmt::format("the next free id is {}, past {}: give the objects "
                                              "smaller ids",
                                              o.id, most));
  return o;
}

}  // namespace

void parse_objects(const Reader& r, const PathContext& ctx, pipeline::Source& s) {
  const toml::node* n = r.node("objects");
  const toml::array* a = n->as_array();
  if (!a || a->empty() || !a->is_array_of_tables())
    throw Error(r.key_path("objects"),
                a && a->empty() ? "needs at least one object"
                                : "expected an array of tables, one [[source.objects]] each");
  if (a->size() > kMaxObjects)
    throw Error(r.key_path("objects"),
                fmt::format("{} objects; a shot assembles at most {}", a->size(), kMaxObjects));
  int next_id = 2;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const std::string key = fmt::format("{}[{}]", r.key_path("objects"), i);
    const Reader o(*(*a)[i].as_table(), key, "source.objects[N]");
    pipeline::SceneObject obj = parse_object(o, ctx, next_id);
    for (std::size_t j = 0; j < s.objects.size(); ++j)
      if (s.objects[j].id == obj.id)
        throw Error(o.key_path("id"),
                    fmt::format("id {} is taken by {}[{}]: ids are unique across objects", obj.id,
                                r.key_path("objects"), j));
    next_id = std::max(next_id, obj.id + 1);
    s.objects.push_back(std::move(obj));
  }
  s.shot.clip = scene::kAssemblyClip;
}

}  // namespace emaki::shot
