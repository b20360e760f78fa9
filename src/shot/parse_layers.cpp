// [exemplars.NAME] and [layers.NAME].
#include <fmt/format.h>

#include <algorithm>

#include "core/shot_keys.h"
#include "shot/parser_sections.h"

namespace emaki::shot {

void parse_exemplar(const Reader& r, const PathContext& ctx, pipeline::Exemplar& e) {
  e.kind = r.choice("kind", e.kind, kExemplarKinds);
  e.painting = ctx.input_file(r, "painting", true);
  e.colorspace = r.string(shot_keys::kColorspace, e.colorspace);
  if (e.kind == pipeline::ExemplarKind::kKeyframe) {
    for (const char* k : {"sphere", "elevation", "horizon", "fov", "light", "softness", "ground",
                          "ground_color", "aa"})
      if (r.has(k)) throw Error(r.key_path(k), "applies to a 'matcap' exemplar only");
    e.passes = ctx.input_file(r, "passes", true);
    return;
  }
  if (r.has("passes")) throw Error(r.key_path("passes"), "applies to a 'keyframe' exemplar only");
  exemplar::ReferenceSpec& ref = e.reference;
  if (r.has("sphere")) {
    const std::vector<float> c = r.numbers("sphere", 3);
    if (!(c[2] > 0.0f))
      throw Error(r.key_path("sphere"), fmt::format("radius must be > 0, got {}", c[2]));
    ref.center = {c[0], c[1]};
    ref.radius = c[2];
  }
  ref.elevation_deg = r.real("elevation", ref.elevation_deg);
  if (r.has("horizon")) ref.horizon_row = r.real("horizon", 0.0f);
  ref.fov_deg = r.real("fov", ref.fov_deg);
  ref.light.direction = r.vec3("light", ref.light.direction);
  if (glm::length(ref.light.direction) == 0.0f)
    throw Error(r.key_path("light"), "must not be [0, 0, 0]");
  ref.light.softness_deg = r.real("softness", ref.light.softness_deg);
  ref.ground = r.boolean("ground", ref.ground);
  const glm::vec3 ground = ref.ground_color;
  const composite::Color g = r.color("ground_color", {ground.r, ground.g, ground.b});
  ref.ground_color = {g.r, g.g, g.b};
  e.aa = r.integer("aa", e.aa);
}

namespace {

void check_exemplar_exists(const Reader& r, const pipeline::Shot& shot, const std::string& name) {
  if (shot.find_exemplar(name)) return;
  std::vector<std::string> names;
  for (const auto& e : shot.exemplars) names.push_back(e.name);
  const std::string near = closest_key(name, names);
  throw Error(
      r.key_path("exemplar"),
      fmt::format("'{}' is not defined in [exemplars]{}", echo(name),
                  near.empty() ? (names.empty() ? std::string(" (there are none)")
                                                : fmt::format(" (defined: {})", join_quoted(names)))
                               : fmt::format(" — did you mean '{}'?", near)));
}

// layers.NAME.guides.PASS.map: a pass of each frame whose values are weights in [0, 1], or a
// painted image (a path, resolved against the shot file's folder).
void parse_weight_map(const Reader& r, const PathContext& ctx, pipeline::GuideSpec& g) {
  const std::string map = r.string("map", "");
  if (map.empty()) throw Error(r.key_path("map"), "must name a pass or an image");
  for (const char* pass : {"diffuse", "shadow", "outline", "alpha"})
    if (map == pass) {
      g.map_pass = map;
      return;
    }
  const std::vector<std::string> passes = pass_names();
  if (std::find(passes.begin(), passes.end(), map) != passes.end())
    throw Error(r.key_path("map"),
                fmt::format("the '{}' pass does not hold weights in [0, 1]; use diffuse, shadow, "
                            "outline or alpha, or a painted image",
                            map));
  g.map_image = ctx.input_file(r, "map", true);
}

// layers.NAME.guides: the passes in the file's order, so that results do not depend on how
// toml++ sorts keys. A pass's value is its weight, or a table with its weight and weight map.
std::vector<pipeline::GuideSpec> parse_guides(const Reader& r, const PathContext& ctx,
                                              const toml::table& t) {
  const Reader g(t, r.key_path("guides"), "layers.NAME.guides", pass_names(), "PASS");
  // (line, column) as int64, since a 1 MB file may hold a million lines.
  std::vector<std::pair<std::string, int64_t>> order;
  for (const auto& [k, v] : t)
    order.emplace_back(std::string(k.str()), int64_t(v.source().begin.line) * 100000000 +
                                                 int64_t(v.source().begin.column));
  std::stable_sort(order.begin(), order.end(),
                   [](auto& a, auto& b) { return a.second < b.second; });
  std::vector<pipeline::GuideSpec> guides;
  for (const auto& [pass, line] : order) {
    if (pass == "motion" || pass == "alpha" || pass == "position" || pass == "depth")
      throw Error(g.key_path(pass),
                  "this pass does not mean the same on the exemplar and the shot; "
                  "use normal, diffuse, shadow, outline, albedo, ...");
    if (const toml::table* sub = g.node(pass)->as_table()) {
      const Reader m(*sub, g.key_path(pass), "layers.NAME.guides.PASS");
      pipeline::GuideSpec spec{pass, m.real("weight", pipeline::GuideSpec{}.weight)};
      if (m.has("map")) parse_weight_map(m, ctx, spec);
      guides.push_back(spec);
    } else {
      guides.push_back({pass, g.real(pass, pipeline::GuideSpec{}.weight)});
    }
  }
  if (guides.empty()) throw Error(r.key_path("guides"), "needs at least one pass");
  return guides;
}

void parse_synthesis(const Reader& r, pipeline::SynthSpec& s) {
  s.patch_size = r.integer("patch_size", s.patch_size);
  if (s.patch_size % 2 == 0)
    throw Error(r.key_path("patch_size"), fmt::format("must be odd, got {}", s.patch_size));
  s.uniformity = r.real("uniformity", s.uniformity);
  s.pyramid_levels = r.integer("pyramid_levels", s.pyramid_levels);
  if (s.pyramid_levels == 0)
    throw Error(r.key_path("pyramid_levels"), "must be >= 1, or -1 for automatic");
  s.search_vote_iters = r.integer("search_vote_iters", s.search_vote_iters);
  s.patch_match_iters = r.integer("patch_match_iters", s.patch_match_iters);
  s.seed = uint64_t(r.integer("seed", int(s.seed)));
}

std::vector<float> unit_numbers(const Reader& r, const toml::array& stop) {
  std::vector<float> v;
  for (const toml::node& e : stop) {
    if (auto i = e.value_exact<int64_t>())
      v.push_back(float(*i));
    else if (auto f = e.value_exact<double>())
      v.push_back(float(*f));
  }
  return v;
}

void parse_gradient(const Reader& r, composite::LayerLook& look) {
  const toml::node* n = r.node("gradient");
  if (!n) return;
  const toml::array* a = n->as_array();
  const char* expected = "an array of [position, r, g, b] stops";
  if (!a) r.type_error("gradient", *n, expected);
  look.gradient.clear();
  for (const toml::node& stop : *a) {
    const toml::array* sa = stop.as_array();
    const std::vector<float> v = sa ? unit_numbers(r, *sa) : std::vector<float>();
    if (!sa || v.size() != 4 || sa->size() != 4)
      throw Error(r.key_path("gradient"), fmt::format("expected {}", expected));
    for (float x : v)
      if (!(x >= 0.0f && x <= 1.0f))
        throw Error(r.key_path("gradient"), fmt::format("values must be in [0, 1], got {}", x));
    if (!look.gradient.empty() && v[0] < look.gradient.back().position)
      throw Error(r.key_path("gradient"), "stops must be sorted by position");
    look.gradient.push_back({v[0], {v[1], v[2], v[3]}});
  }
  if (look.gradient.empty()) throw Error(r.key_path("gradient"), "needs at least one stop");
  if (look.source != composite::ColorSource::kGradient && !r.has("color"))
    look.source = composite::ColorSource::kGradient;
}

void parse_colour(const Reader& r, composite::LayerLook& look) {
  if (const toml::node* n = r.node("color")) {
    if (n->is_string())
      look.source = r.choice("color", composite::ColorSource::kAlbedo, kColorSources);
    else if (n->is_array())
      look.source = composite::ColorSource::kFlat, look.flat = r.color("color", look.flat);
    else
      r.type_error("color", *n, "\"albedo\", \"gradient\" or [r, g, b]");
  }
  parse_gradient(r, look);
  if (look.source == composite::ColorSource::kGradient && look.gradient.empty())
    throw Error(r.key_path("gradient"), "is required with color = \"gradient\"");
  look.alpha_from = r.choice("alpha", look.alpha_from, kAlphaFroms);
  look.blend = r.choice("blend", look.blend, kBlendModes);
}

void parse_filters(const Reader& r, composite::Filters& f) {
  if (r.has("levels")) {
    const std::vector<float> v = r.numbers("levels", 3);
    if (!(v[0] < v[1]))
      throw Error(r.key_path("levels"), fmt::format("black {} must be below white {}", v[0], v[1]));
    if (!(v[2] > 0.0f))
      throw Error(r.key_path("levels"), fmt::format("gamma must be > 0, got {}", v[2]));
    f.in_black = v[0], f.in_white = v[1], f.gamma = v[2];
  }
  if (r.has("output_levels")) {
    const std::vector<float> v = r.numbers("output_levels", 2);
    for (float x : v)
      if (!(x >= 0.0f && x <= 1.0f))
        throw Error(r.key_path("output_levels"),
                    fmt::format("values must be in [0, 1], got {}", x));
    f.out_black = v[0], f.out_white = v[1];
  }
  f.tint = r.color("tint", f.tint);
  f.hue_deg = r.real("hue", f.hue_deg);
  f.saturation = r.real("saturation", f.saturation);
  f.opacity = r.real("opacity", f.opacity);
}

}  // namespace

void parse_layer(const Reader& r, const pipeline::Shot& shot, pipeline::Layer& l) {
  l.kind = r.choice("kind", l.kind, kLayerKinds);
  const KindDefaults d = kind_defaults(l.kind);
  l.exemplar = r.string("exemplar", "");
  if (l.exemplar.empty())
    throw Error(r.key_path("exemplar"), "is required (an [exemplars.NAME] table)");
  check_exemplar_exists(r, shot, l.exemplar);
  l.guides = d.guides;
  const PathContext ctx{std::filesystem::path(shot.path).parent_path()};
  if (const toml::table* t = r.table("guides")) l.guides = parse_guides(r, ctx, *t);
  if (l.guides.empty()) throw Error(r.key_path("guides"), "is required for a 'custom' layer");
  parse_synthesis(r, l.synth);
  l.single_colour = r.boolean("single_colour", l.single_colour);
  l.channel = r.choice("channel", l.channel, kTouchChannels);
  l.temporal.enabled = r.boolean("temporal", l.temporal.enabled);
  l.temporal.weight = r.real("temporal_weight", d.temporal_weight);
  l.temporal.guide = r.choice("advection", l.temporal.guide, kAdvectionGuides);
  l.temporal.confidence = r.boolean("temporal_confidence", l.temporal.confidence);
  l.temporal.uniformity = r.real("temporal_uniformity", d.temporal_uniformity);
  l.temporal.anchor = d.temporal_anchor;
  l.temporal.flat_uniformity = d.temporal_flat_uniformity ? l.synth.uniformity : 0.0f;
  l.temporal.ink_ratio = d.temporal_ink_refresh > 0 ? 1.0f : 0.0f;
  l.temporal.ink_refresh = d.temporal_ink_refresh;
  l.temporal.ink_confident = d.temporal_ink_confident;
  l.temporal.ink_objects = l.temporal.ink_blend = d.temporal_ink_objects;
  l.temporal.coherence_radius = d.temporal_coherence ? -1 : 0;
  l.temporal.warm_patch_match_iters = d.temporal_warm_sweeps;
  l.temporal.warm_start = r.boolean("temporal_warm_start", l.temporal.warm_start);
  l.temporal.keep_every_field =
      r.choice("temporal_fields", l.temporal.keep_every_field, kKeptFields);
  l.mask = d.mask;
  l.mask.kind = r.choice("mask", d.mask.kind, kMaskKinds);
  l.mask.dilate = r.real("mask_dilate", l.mask.dilate);
  l.mask.threshold = r.real("mask_threshold", l.mask.threshold);
  l.order = r.integer("order", l.order);
  l.look = d.look;
  parse_colour(r, l.look);
  parse_filters(r, l.look.filters);
}

}  // namespace emaki::shot
