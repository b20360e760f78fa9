// Every key's default is written in one place in code, the struct's initialiser
// (pipeline/shot_description.h and the scene/render/exemplar/composite structs it holds): the
// parser falls back to the member it fills. The schema's text (and docs/shot_file.md made from
// it) says the same again for people; these tests check the two agree, key by key, both on
// default-constructed structs and on what the parser makes of a file that sets nothing.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>

#include "core/limits.h"
#include "shot/kinds.h"
#include "shot/parser.h"
#include "shot/schema.h"

namespace emaki::shot {
namespace {

using pipeline::Shot;

std::string text(float v) {
  return fmt::format("{}", v);
}
std::string text(bool v) {
  return v ? "true" : "false";
}
std::string text(int64_t v) {
  return fmt::format("{}", v);
}
std::string text(int v) {
  return fmt::format("{}", v);
}
std::string text(glm::vec3 v) {
  return fmt::format("[{}, {}, {}]", v.x, v.y, v.z);
}
std::string text(composite::Color c) {
  return text(glm::vec3(c.r, c.g, c.b));
}
template <typename E, std::size_t N>
std::string text(E value, const Named<E> (&names)[N]) {
  return std::string(name_of(std::span<const Named<E>>(names), value));
}

const pipeline::Layer& layer(const Shot& s) {
  return s.layers.at(0);
}
const pipeline::Exemplar& exemplar(const Shot& s) {
  return s.exemplars.at(0);
}
pipeline::SceneObject object(const Shot& s) {
  return s.source.objects.empty() ? pipeline::SceneObject{} : s.source.objects[0];
}
const scene::CameraSpec& camera(const Shot& s) {
  return s.source.shot.camera;
}

using Value = std::function<std::string(const Shot&)>;

// The value each key with a written default sets, as the schema's text shows it.
const std::map<std::string, Value> kValues = {
    {"threads", [](const Shot& s) { return text(s.threads); }},
    {"limits.max_pixels",
     [](const Shot& s) { return text(s.max_pixels ? s.max_pixels : kDefaultMaxPixels); }},
    {"source.objects[N].translate", [](const Shot& s) { return text(object(s).translate); }},
    {"source.objects[N].rotate", [](const Shot& s) { return text(object(s).rotate_deg); }},
    {"source.objects[N].scale", [](const Shot& s) { return text(object(s).scale.x); }},
    {"source.objects[N].velocity", [](const Shot& s) { return text(object(s).velocity); }},
    {"source.objects[N].start", [](const Shot& s) { return text(object(s).start); }},
    {"source.objects[N].loop", [](const Shot& s) { return text(object(s).loop); }},
    {"source.fps", [](const Shot& s) { return text(s.source.fps); }},
    {"source.start", [](const Shot& s) { return text(s.source.shot.start_time); }},
    {"source.loop", [](const Shot& s) { return text(s.source.shot.loop); }},
    {"source.aa", [](const Shot& s) { return text(s.source.render.aa); }},
    {"source.outline_width", [](const Shot& s) { return text(s.source.render.outline_width); }},
    {"source.crease", [](const Shot& s) { return text(s.source.render.crease_deg); }},
    {"source.background", [](const Shot& s) { return text(s.source.shot.background); }},
    {"source.camera.mode", [](const Shot& s) { return text(camera(s).mode, kCameraModes); }},
    {"source.camera.position", [](const Shot& s) { return text(camera(s).position); }},
    {"source.camera.azimuth", [](const Shot& s) { return text(camera(s).azimuth_deg); }},
    {"source.camera.elevation", [](const Shot& s) { return text(camera(s).elevation_deg); }},
    {"source.camera.distance", [](const Shot& s) { return text(camera(s).distance); }},
    {"source.camera.fov", [](const Shot& s) { return text(camera(s).fov_deg); }},
    {"source.camera.orthographic", [](const Shot& s) { return text(camera(s).orthographic); }},
    {"source.camera.ortho_height", [](const Shot& s) { return text(camera(s).ortho_height); }},
    {"source.camera.gltf_node", [](const Shot& s) { return text(camera(s).gltf_node); }},
    {"source.camera.orbit", [](const Shot& s) { return text(camera(s).orbit_deg); }},
    {"source.camera.dolly", [](const Shot& s) { return text(camera(s).dolly); }},
    {"source.camera.pan", [](const Shot& s) { return text(camera(s).pan); }},
    {"source.light.direction", [](const Shot& s) { return text(s.source.shot.light.direction); }},
    {"source.light.world",
     [](const Shot& s) { return text(!s.source.shot.light.camera_relative); }},
    {"source.light.softness", [](const Shot& s) { return text(s.source.shot.light.softness_deg); }},
    {"source.light.turn", [](const Shot& s) { return text(s.source.shot.light.turn_deg); }},
    {"source.ground.enabled", [](const Shot& s) { return text(s.source.shot.ground.enabled); }},
    {"source.ground.size", [](const Shot& s) { return text(s.source.shot.ground.size); }},
    {"source.ground.color", [](const Shot& s) { return text(s.source.shot.ground.color); }},
    {"source.preset", [](const Shot& s) { return text(s.source.preset, kSourcePresets); }},
    {"source.view_layer", [](const Shot& s) { return s.source.view_layer; }},
    {"source.normals", [](const Shot& s) { return text(s.source.world_normals, kNormalSpaces); }},
    {"source.up", [](const Shot& s) { return text(s.source.z_up, kUpAxes); }},
    {"source.premultiplied", [](const Shot& s) { return text(s.source.premultiplied); }},
    {"source.passes_colorspace", [](const Shot& s) { return s.source.passes_colorspace; }},
    {"exemplars.NAME.colorspace", [](const Shot& s) { return exemplar(s).colorspace; }},
    {"exemplars.NAME.kind", [](const Shot& s) { return text(exemplar(s).kind, kExemplarKinds); }},
    {"exemplars.NAME.elevation",
     [](const Shot& s) { return text(exemplar(s).reference.elevation_deg); }},
    {"exemplars.NAME.fov", [](const Shot& s) { return text(exemplar(s).reference.fov_deg); }},
    {"exemplars.NAME.light",
     [](const Shot& s) { return text(exemplar(s).reference.light.direction); }},
    {"exemplars.NAME.softness",
     [](const Shot& s) { return text(exemplar(s).reference.light.softness_deg); }},
    {"exemplars.NAME.ground", [](const Shot& s) { return text(exemplar(s).reference.ground); }},
    {"exemplars.NAME.ground_color",
     [](const Shot& s) { return text(exemplar(s).reference.ground_color); }},
    {"exemplars.NAME.aa", [](const Shot& s) { return text(exemplar(s).aa); }},
    {"layers.NAME.kind", [](const Shot& s) { return text(layer(s).kind, kLayerKinds); }},
    {"layers.NAME.guides.PASS.weight",
     [](const Shot& s) { return text(layer(s).guides.at(0).weight); }},
    {"layers.NAME.patch_size", [](const Shot& s) { return text(layer(s).synth.patch_size); }},
    {"layers.NAME.uniformity", [](const Shot& s) { return text(layer(s).synth.uniformity); }},
    {"layers.NAME.pyramid_levels",
     [](const Shot& s) { return text(layer(s).synth.pyramid_levels); }},
    {"layers.NAME.search_vote_iters",
     [](const Shot& s) { return text(layer(s).synth.search_vote_iters); }},
    {"layers.NAME.patch_match_iters",
     [](const Shot& s) { return text(layer(s).synth.patch_match_iters); }},
    {"layers.NAME.seed", [](const Shot& s) { return text(int64_t(layer(s).synth.seed)); }},
    {"layers.NAME.single_colour", [](const Shot& s) { return text(layer(s).single_colour); }},
    {"layers.NAME.channel", [](const Shot& s) { return text(layer(s).channel, kTouchChannels); }},
    {"layers.NAME.temporal", [](const Shot& s) { return text(layer(s).temporal.enabled); }},
    {"layers.NAME.temporal_weight", [](const Shot& s) { return text(layer(s).temporal.weight); }},
    {"layers.NAME.temporal_confidence",
     [](const Shot& s) { return text(layer(s).temporal.confidence); }},
    {"layers.NAME.temporal_uniformity",
     [](const Shot& s) { return text(layer(s).temporal.uniformity); }},
    {"layers.NAME.temporal_warm_start",
     [](const Shot& s) { return text(layer(s).temporal.warm_start); }},
    {"layers.NAME.temporal_fields",
     [](const Shot& s) { return text(layer(s).temporal.keep_every_field, kKeptFields); }},
    {"layers.NAME.advection",
     [](const Shot& s) { return text(layer(s).temporal.guide, kAdvectionGuides); }},
    {"layers.NAME.mask", [](const Shot& s) { return text(layer(s).mask.kind, kMaskKinds); }},
    {"layers.NAME.mask_dilate", [](const Shot& s) { return text(layer(s).mask.dilate); }},
    {"layers.NAME.mask_threshold", [](const Shot& s) { return text(layer(s).mask.threshold); }},
    {"layers.NAME.order", [](const Shot& s) { return text(layer(s).order); }},
    {"layers.NAME.alpha",
     [](const Shot& s) { return text(layer(s).look.alpha_from, kAlphaFroms); }},
    {"layers.NAME.blend", [](const Shot& s) { return text(layer(s).look.blend, kBlendModes); }},
    {"layers.NAME.levels",
     [](const Shot& s) {
       const composite::Filters& f = layer(s).look.filters;
       return text(glm::vec3(f.in_black, f.in_white, f.gamma));
     }},
    {"layers.NAME.output_levels",
     [](const Shot& s) {
       const composite::Filters& f = layer(s).look.filters;
       return fmt::format("[{}, {}]", f.out_black, f.out_white);
     }},
    {"layers.NAME.tint", [](const Shot& s) { return text(layer(s).look.filters.tint); }},
    {"layers.NAME.hue", [](const Shot& s) { return text(layer(s).look.filters.hue_deg); }},
    {"layers.NAME.saturation",
     [](const Shot& s) { return text(layer(s).look.filters.saturation); }},
    {"layers.NAME.opacity", [](const Shot& s) { return text(layer(s).look.filters.opacity); }},
    {"compositing.paper_scale", [](const Shot& s) { return text(s.compositing.paper_scale); }},
    {"compositing.paper_color", [](const Shot& s) { return text(s.compositing.paper_color); }},
    {"compositing.paper_colorspace", [](const Shot& s) { return s.compositing.paper_colorspace; }},
    {"compositing.space",
     [](const Shot& s) { return text(s.compositing.space, kCompositingSpaces); }},
    {"outputs.layer_png", [](const Shot& s) { return text(s.outputs.layer_png); }},
    {"outputs.composite_png", [](const Shot& s) { return text(s.outputs.composite_png); }},
    {"outputs.composite_exr", [](const Shot& s) { return text(s.outputs.composite_exr); }},
    {"outputs.layered_exr", [](const Shot& s) { return text(s.outputs.layered_exr); }},
    {"outputs.mp4", [](const Shot& s) { return text(s.outputs.mp4); }},
    {"outputs.contact_sheet", [](const Shot& s) { return text(s.outputs.contact_sheet); }},
    {"outputs.crf", [](const Shot& s) { return text(s.outputs.crf); }},
};

// The schema's default as a value: the first `...` of its text ("*kind* (`1`; ...)" gives the
// `custom` kind's), without quotes; empty when it names no value ("required", "first clip").
std::string written_default(const KeySpec& k) {
  const std::string_view d = k.default_value;
  const std::size_t b = d.find('`');
  if (b == std::string_view::npos) return "";
  const std::size_t e = d.find('`', b + 1);
  std::string v(d.substr(b + 1, e - b - 1));
  if (v.size() >= 2 && v.front() == '"' && v.back() == '"') v = v.substr(1, v.size() - 2);
  return v;
}

// Every key whose schema text gives a value has a check below, and every check a key.
TEST(SchemaDefaults, EveryWrittenDefaultIsChecked) {
  int written = 0;
  for (const KeySpec& k : schema()) {
    if (written_default(k).empty()) continue;
    ++written;
    EXPECT_TRUE(kValues.count(std::string(k.key)))
        << k.key << ": the schema gives a default (" << k.default_value
        << ") that schema_defaults_test does not check";
  }
  for (const auto& [key, value] : kValues) EXPECT_NE(find_key(key), nullptr) << key;
  EXPECT_EQ(written, int(kValues.size()));
}

void expect_schema_defaults(const Shot& shot, const std::string& what) {
  for (const auto& [key, value] : kValues) {
    const KeySpec* k = find_key(key);
    if (!k) continue;
    EXPECT_EQ(value(shot), written_default(*k))
        << key << ": the schema's text says " << k->default_value << ", " << what << " gives "
        << value(shot);
  }
}

// The structs' initialisers, which the parser falls back to.
TEST(SchemaDefaults, StructInitialisersAreTheSchemas) {
  Shot shot;
  shot.exemplars.emplace_back();
  shot.layers.emplace_back();
  shot.layers[0].guides.emplace_back();
  shot.source.objects.emplace_back();
  expect_schema_defaults(shot, "the struct's initialiser");
}

// `source`: keys of [source]; `tables`: the tables under it.
std::string minimal_shot(const std::string& source, const std::string& tables) {
  const std::string data = EMAKI_TEST_DATA;
  return "[source]\n" + source + "frames = [0, 3]\nsize = [64, 48]\n" + tables +
         "[source.camera]\n[source.light]\n[source.ground]\n"
         "[exemplars.sphere]\npainting = \"" +
         data +
         "/stylit/source_style.png\"\n"
         "[layers.paint]\nexemplar = \"sphere\"\n[layers.paint.guides.normal]\n"
         "[compositing]\n"
         "[outputs]\nfolder = \"/tmp/emaki_schema_defaults_test_out\"\n";
}

// What the parser makes of a file that sets none of the keys (every table given, empty).
TEST(SchemaDefaults, ParserDefaultsAreTheSchemas) {
  const std::string data = EMAKI_TEST_DATA;
  expect_schema_defaults(
      parse_shot(minimal_shot("scene = \"" + data + "/scenes/Fox.glb\"\n", ""), "/tmp/shot.toml"),
      "the parser");
  const Shot objects =
      parse_shot(minimal_shot("", "[[source.objects]]\nscene = \"" + data + "/scenes/Fox.glb\"\n"),
                 "/tmp/shot.toml");
  ASSERT_EQ(objects.source.objects.size(), 1u);
  expect_schema_defaults(objects, "the parser (source.objects)");
}

}  // namespace
}  // namespace emaki::shot
