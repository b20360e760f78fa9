#include "store/settings_manifests.h"

#include <fmt/format.h>

#include <filesystem>
#include <glm/glm.hpp>
#include <set>

#include "core/version.h"

namespace emaki::io {

namespace fs = std::filesystem;

namespace {

// Where an input is, written for whoever reads the manifest (the comparison leaves it out: its
// digest line says what the file is).
std::string canonical(const std::string& path) {
  std::error_code ec;
  const fs::path c = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? path : c.string();
}

// A frame pattern's folder made canonical (the pattern itself names no file).
std::string canonical_pattern(const std::string& pattern) {
  const fs::path p(pattern);
  return (fs::path(canonical(p.parent_path().empty() ? "." : p.parent_path().string())) /
          p.filename())
      .string();
}

std::string key_of(const std::string& line) {
  return line.substr(0, line.find(" = "));
}

std::string v2(const glm::vec2& v) {
  return fmt::format("{} {}", v.x, v.y);
}
std::string v3(const glm::vec3& v) {
  return fmt::format("{} {} {}", v.x, v.y, v.z);
}

struct Lines {
  Manifest m;
  template <typename T>
  void add(const std::string& key, const T& value) {
    m.push_back(fmt::format("{} = {}", key, value));
  }
};

void add_light(Lines& l, const std::string& p, const scene::LightSpec& s) {
  l.add(p + "direction", v3(s.direction));
  l.add(p + "camera_relative", s.camera_relative);
  l.add(p + "softness", s.softness_deg);
}

void add_object(Lines& l, std::size_t i, const pipeline::SceneObject& o) {
  const std::string p = fmt::format("source.objects[{}]", i);
  l.add(p + ".scene", canonical(o.scene));
  l.add(p + ".scene.digest", file_digest(o.scene));
  l.add(p, fmt::format("translate {} rotate {} scale {} velocity {} clip {} start {} loop {} id {}",
                       v3(o.translate), v3(o.rotate_deg), v3(o.scale), v3(o.velocity), o.clip,
                       o.start, o.loop, o.id));
}

// Everything that decides the guide passes of a frame.
void add_source(Lines& l, const pipeline::Shot& shot) {
  const pipeline::Source& s = shot.source;
  l.add("size", fmt::format("{}x{}", s.width, s.height));
  // The temporal chain starts at the first frame: every later frame depends on it.
  l.add("source.first_frame", s.first_frame);
  if (s.kind == pipeline::SourceKind::kScene) {
    if (s.objects.empty()) {
      l.add("source.scene", canonical(s.scene_path));
      l.add("source.scene.digest", file_digest(s.scene_path));
    }
    for (std::size_t i = 0; i < s.objects.size(); ++i) add_object(l, i, s.objects[i]);
    const scene::ShotSpec& sh = s.shot;
    const scene::CameraSpec& c = sh.camera;
    l.add("source.camera",
          fmt::format("mode {} position {} target {} has_target {} azimuth {} elevation {} "
                      "distance {} fov {} ortho {} {} node {} orbit {} dolly {} pan {} shift {}",
                      int(c.mode), v3(c.position), v3(c.target), c.has_target, c.azimuth_deg,
                      c.elevation_deg, c.distance, c.fov_deg, c.orthographic, c.ortho_height,
                      c.gltf_node, c.orbit_deg, c.dolly, v3(c.pan), v2(c.shift)));
    add_light(l, "source.light.", sh.light);
    l.add("source.ground",
          fmt::format("{} {} {} {} {}", sh.ground.enabled, sh.ground.size, sh.ground.height,
                      sh.ground.auto_height, v3(sh.ground.color)));
    l.add("source.background", v3(sh.background));
    l.add("source.clip", sh.clip);
    l.add("source.time", fmt::format("fps {} start {} loop {}", sh.fps, sh.start_time, sh.loop));
    const render::RenderOptions& r = s.render;
    l.add("source.render",
          fmt::format("aa {} outline {} crease {} depth_jump {} shadow_map {}", r.aa,
                      r.outline_width, r.crease_deg, r.depth_jump, r.shadow_map_size));
  } else {
    // A sequence's frames are not hashed (they may be gigabytes): its pattern and conventions.
    l.add("source.sequence", canonical_pattern(s.pattern));
    l.add("source.preset",
          fmt::format("{} {} world_normals {} z_up {} premultiplied {}",
                      s.preset == pipeline::SourcePreset::kBlender ? "blender" : "emaki",
                      s.view_layer, s.world_normals, s.z_up, s.premultiplied));
    if (s.passes_colorspace != pipeline::Source{}.passes_colorspace)
      l.add("source.passes_colorspace", s.passes_colorspace);
    for (const pipeline::ChannelMapping& m : s.channels)
      l.add("source.channels." + m.pass, fmt::format("{}", fmt::join(m.channels, " ")));
  }
}

// What a MatCap-like exemplar's reference passes are rendered from (but the painting's size).
void add_reference(Lines& l, const std::string& p, const pipeline::Exemplar& e) {
  const exemplar::ReferenceSpec& r = e.reference;
  l.add(p + "reference",
        fmt::format("center {} radius {} elevation {} horizon {} fov {} ground {} {} "
                    "background {} aa {}",
                    v2(r.center), r.radius, r.elevation_deg, r.horizon_row, r.fov_deg, r.ground,
                    v3(r.ground_color), v3(r.background), e.aa));
  add_light(l, p + "light.", r.light);
}

void add_exemplar(Lines& l, const pipeline::Exemplar& e) {
  const std::string p = "exemplars." + e.name + ".";
  l.add(p + "kind", int(e.kind));
  l.add(p + "painting", canonical(e.painting));
  l.add(p + "painting.digest", file_digest(e.painting));
  // Only when not the default, so that outputs made before the key existed stay current.
  if (e.colorspace != pipeline::Exemplar{}.colorspace) l.add(p + "colorspace", e.colorspace);
  if (e.scale != 1.0) l.add(p + "scale", e.scale);
  if (e.kind == pipeline::ExemplarKind::kMatcap) {
    add_reference(l, p, e);
  } else {
    l.add(p + "passes", canonical(e.passes));
    l.add(p + "passes.digest", file_digest(e.passes));
  }
}

}  // namespace

Manifest layer_manifest(const pipeline::Shot& shot, const pipeline::Layer& layer) {
  Lines l;
  l.add("outputs_format", kOutputsFormat);
  l.add(kVersionKey, version());
  add_source(l, shot);
  const std::string p = "layers." + layer.name + ".";
  l.add(p + "exemplar", layer.exemplar);
  if (!shot.colour.config.empty()) l.add("colour.config", canonical(shot.colour.config));
  if (const pipeline::Exemplar* e = shot.find_exemplar(layer.exemplar)) add_exemplar(l, *e);
  for (const pipeline::GuideSpec& g : layer.guides) {
    l.add(p + "guides." + g.pass, g.weight);
    if (!g.map_pass.empty()) l.add(p + "guides." + g.pass + ".map", "pass " + g.map_pass);
    if (!g.map_image.empty()) {
      l.add(p + "guides." + g.pass + ".map", canonical(g.map_image));
      l.add(p + "guides." + g.pass + ".map.digest", file_digest(g.map_image));
    }
  }
  const pipeline::SynthSpec& s = layer.synth;
  l.add(p + "synth", fmt::format("patch {} uniformity {} levels {} search_vote {} "
                                 "patch_match {} seed {}",
                                 s.patch_size, s.uniformity, s.pyramid_levels, s.search_vote_iters,
                                 s.patch_match_iters, s.seed));
  l.add(p + "single_colour", layer.single_colour);
  l.add(p + "channel", layer.channel);
  l.add(p + "temporal",
        fmt::format("{} weight {} guide {} warm_start {}", layer.temporal.enabled,
                    layer.temporal.weight, int(layer.temporal.guide), layer.temporal.warm_start));
  const temporal::ConfidenceParams& c = layer.temporal.confidence_params;
  l.add(
      p + "temporal.confidence",
      fmt::format("{} error {} {} foreign {} erode {} uniformity {}", layer.temporal.confidence,
                  c.error_full, c.error_none, c.foreign_none, c.erode, layer.temporal.uniformity));
  const pipeline::TemporalSpec& t = layer.temporal;
  l.add(p + "temporal.chain",
        fmt::format("guide_sigma {} sharp {} reseed {} change {} {} anchor {} sigma {} rate {} "
                    "holes {} finest {} schedule {} {} coherence {}",
                    t.guide_sigma, t.sharp_estimate, t.reseed, c.change_full, c.change_none,
                    t.anchor, t.anchor_sigma, t.anchor_rate, t.anchor_holes, t.anchor_finest_iters,
                    t.finest_iters, t.warm_patch_match_iters, t.coherence_radius));
  l.add(p + "mask", fmt::format("{} dilate {} threshold {}", int(layer.mask.kind),
                                layer.mask.dilate, layer.mask.threshold));
  return l.m;
}

Manifest reference_manifest(const pipeline::Exemplar& exemplar, int width, int height) {
  Lines l;
  l.add("outputs_format", kOutputsFormat);
  l.add("size", fmt::format("{}x{}", width, height));
  add_reference(l, "", exemplar);
  return l.m;
}

Manifest passes_manifest(const pipeline::Shot& shot) {
  Lines l;
  l.add("outputs_format", kOutputsFormat);
  l.add(kVersionKey, version());
  add_source(l, shot);
  // An automatic camera frames the whole range.
  l.add("source.last_frame", shot.source.last_frame);
  return l.m;
}

Manifest frames_manifest(const pipeline::Shot& shot) {
  Lines l;
  l.add("outputs_format", kOutputsFormat);
  l.add(kVersionKey, version());
  l.add("size", fmt::format("{}x{}", shot.source.width, shot.source.height));
  // The layered EXR's channels: one group per layer, in compositing order.
  for (const pipeline::Layer& layer : shot.layers)
    l.add("layers." + layer.name + ".single_colour", layer.single_colour);
  return l.m;
}

namespace {

// The lines manifest_current compares: path lines with a digest beside them dropped, a
// sequence's pattern made canonical (older manifests spelled it as the command line did).
Manifest comparable(const Manifest& m) {
  std::set<std::string> digested;
  for (const std::string& line : m) {
    const std::string key = key_of(line);
    constexpr std::string_view kDigest = ".digest";
    if (key.size() > kDigest.size() && key.ends_with(kDigest))
      digested.insert(key.substr(0, key.size() - kDigest.size()));
  }
  Manifest out;
  for (const std::string& line : m) {
    const std::string key = key_of(line);
    if (digested.count(key) || key == kVersionKey) continue;
    if (key == "source.sequence" && line.size() > key.size() + 3)
      out.push_back(key + " = " + canonical_pattern(line.substr(key.size() + 3)));
    else
      out.push_back(line);
  }
  return out;
}

}  // namespace

bool manifest_current(const Manifest& have, const Manifest& want) {
  return comparable(have) == comparable(want);
}

std::string manifest_change(const Manifest& have, const Manifest& want) {
  return manifest_difference(comparable(have), comparable(want));
}

}  // namespace emaki::io
