// [source]: where each frame's guide passes come from.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>

#include "io/image_io.h"
#include "io/input_file.h"
#include "render/passes.h"
#include "shot/parser_sections.h"
#include "store/frame_sequence.h"
#include "store/studio_passes.h"

namespace emaki::shot {

namespace fs = std::filesystem;

namespace {

// The frame-number pattern is parsed here, never handed to printf: a width from the file
// ("%2000000000d") would otherwise ask for gigabytes of padding.
void check_pattern(const std::string& key, const std::string& pattern) {
  int count = 0;
  for (std::size_t i = 0; i < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    std::size_t j = i + 1;
    int width = 0;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) {
      width = width * 10 + (pattern[j++] - '0');
      if (width > io::kMaxFrameWidth)
        throw Error(key, fmt::format("'{}': the frame number's width must be at most {}",
                                     echo_path(pattern), io::kMaxFrameWidth));
    }
    if (j >= pattern.size() || pattern[j] != 'd')
      throw Error(key, fmt::format("'{}': only %d or %0Nd may follow '%'", echo_path(pattern)));
    ++count;
    i = j;
  }
  if (count != 1)
    throw Error(
        key, fmt::format("'{}' must contain exactly one frame number (%04d)", echo_path(pattern)));
}

// source.frames: checked as int64 before narrowing, so 4294967297 cannot quietly become 1.
void parse_frames(const Reader& r, pipeline::Source& s) {
  if (!r.has("frames")) throw Error(r.key_path("frames"), "is required ([first, last])");
  const toml::node* n = r.node("frames");
  const toml::array* a = n->as_array();
  if (!a) r.type_error("frames", *n, "[first, last]");
  if (a->size() != 2)
    throw Error(r.key_path("frames"), fmt::format("expected [first, last], got {} value{}",
                                                  a->size(), a->size() == 1 ? "" : "s"));
  int64_t f[2];
  for (int k = 0; k < 2; ++k) {
    auto i = (*a)[k].value_exact<int64_t>();
    if (!i)
      throw Error(r.key_path("frames"),
                  fmt::format("expected integers, found {}", type_name((*a)[k])));
    if (*i < 0 || *i > kMaxFrame)
      throw Error(r.key_path("frames"),
                  fmt::format("frames must be in [0, {}], got {}", kMaxFrame, *i));
    f[k] = *i;
  }
  if (f[1] < f[0])
    throw Error(r.key_path("frames"),
                fmt::format("the range [{}, {}] is reversed (last before first)", f[0], f[1]));
  if (f[1] - f[0] + 1 > kMaxFrameCount)
    throw Error(r.key_path("frames"), fmt::format("[{}, {}] is {} frames; a shot holds at most {}",
                                                  f[0], f[1], f[1] - f[0] + 1, kMaxFrameCount));
  s.first_frame = int(f[0]);
  s.last_frame = int(f[1]);
}

void parse_camera(const Reader& r, scene::CameraSpec& c) {
  c.mode = r.choice("mode", c.mode, kCameraModes);
  c.position = r.vec3("position", c.position);
  if (r.has("target")) c.target = r.vec3("target", c.target), c.has_target = true;
  c.azimuth_deg = r.real("azimuth", c.azimuth_deg);
  c.elevation_deg = r.real("elevation", c.elevation_deg);
  c.distance = r.real("distance", c.distance);
  c.fov_deg = r.real("fov", c.fov_deg);
  c.orthographic = r.boolean("orthographic", c.orthographic);
  c.ortho_height = r.real("ortho_height", c.ortho_height);
  c.gltf_node = r.integer("gltf_node", c.gltf_node);
  if (c.mode == scene::CameraSpec::Mode::kGltf && c.gltf_node < 0)
    throw Error(r.key_path("gltf_node"), "is required with mode = \"gltf\"");
  c.orbit_deg = r.real("orbit", c.orbit_deg);
  c.dolly = r.real("dolly", c.dolly);
  c.pan = r.vec3("pan", c.pan);
}

void parse_light_and_ground(const Reader& r, scene::ShotSpec& shot) {
  if (const toml::table* t = r.table("light")) {
    Reader l(*t, r.key_path("light"), "source.light");
    shot.light.direction = l.vec3("direction", shot.light.direction);
    if (glm::length(shot.light.direction) == 0.0f)
      throw Error(l.key_path("direction"), "must not be [0, 0, 0]");
    shot.light.camera_relative = !l.boolean("world", !shot.light.camera_relative);
    shot.light.softness_deg = l.real("softness", shot.light.softness_deg);
    shot.light.turn_deg = l.real("turn", shot.light.turn_deg);
  }
  if (const toml::table* t = r.table("ground")) {
    Reader g(*t, r.key_path("ground"), "source.ground");
    shot.ground.enabled = g.boolean("enabled", shot.ground.enabled);
    shot.ground.size = g.real("size", shot.ground.size);
    if (g.has("height"))
      shot.ground.height = g.real("height", 0.0f), shot.ground.auto_height = false;
    const glm::vec3 d = shot.ground.color;
    const composite::Color c = g.color("color", {d.r, d.g, d.b});
    shot.ground.color = {c.r, c.g, c.b};
  }
}

void parse_scene_source(const Reader& r, const PathContext& ctx, pipeline::Source& s) {
  s.kind = pipeline::SourceKind::kScene;
  if (r.has("objects")) {
    for (const char* k : {"clip", "start", "loop"})
      if (r.has(k)) throw Error(r.key_path(k), "applies to 'scene'; each of 'objects' has its own");
  } else {
    s.scene_path = ctx.input_file(r, "scene", true);
  }
  if (!r.has("size")) throw Error(r.key_path("size"), "is required ([width, height])");
  const std::vector<float> size = r.numbers("size", 2);
  for (float v : size)
    if (v < 1 || v > 16384 || v != std::floor(v))
      throw Error(r.key_path("size"),
                  fmt::format("width and height must be integers in [1, 16384], got {}", v));
  s.width = int(size[0]);
  s.height = int(size[1]);
  check_pixel_budget(r.key_path("size"), s.width, s.height);
  s.shot.clip = r.string("clip", s.shot.clip);
  s.shot.start_time = r.real("start", s.shot.start_time);
  s.shot.loop = r.boolean("loop", s.shot.loop);
  s.shot.fps = s.fps;
  s.shot.first_frame = s.first_frame;
  s.shot.last_frame = s.last_frame;
  s.shot.background = r.vec3("background", s.shot.background);
  s.render.width = s.width;
  s.render.height = s.height;
  s.render.aa = r.integer("aa", s.render.aa);
  s.render.outline_width = r.real("outline_width", s.render.outline_width);
  s.render.crease_deg = r.real("crease", s.render.crease_deg);
  if (const toml::table* t = r.table("camera")) {
    Reader c(*t, r.key_path("camera"), "source.camera");
    parse_camera(c, s.shot.camera);
    if (r.has("objects") && s.shot.camera.mode == scene::CameraSpec::Mode::kGltf)
      throw Error(c.key_path("mode"), "\"gltf\" needs 'scene': objects bring no camera");
  }
  if (r.has("objects")) parse_objects(r, ctx, s);
  parse_light_and_ground(r, s.shot);
  for (const char* k :
       {"channels", "preset", "view_layer", "normals", "up", "premultiplied", "passes_colorspace"})
    if (r.has(k)) throw Error(r.key_path(k), "applies to a 'sequence' source only");
}

void parse_channel_mapping(const Reader& r, pipeline::Source& s) {
  const toml::table* t = r.table("channels");
  if (!t) return;
  const std::vector<std::string> passes = pass_names();
  Reader m(*t, r.key_path("channels"), "source.channels", passes, "PASS");
  for (const std::string& pass : passes) {
    const toml::node* n = m.node(pass);
    if (!n) continue;
    const toml::array* a = n->as_array();
    const render::PassInfo* info = render::find_pass(pass);
    const std::string expected = fmt::format("an array of {} channel names", info->count);
    if (!a) m.type_error(pass, *n, expected.c_str());
    pipeline::ChannelMapping cm{pass, {}};
    for (const toml::node& e : *a) {
      auto str = e.value_exact<std::string>();
      if (!str) throw Error(m.key_path(pass), fmt::format("expected {}", expected));
      cm.channels.push_back(*str);
    }
    if (int(cm.channels.size()) != info->count)
      throw Error(m.key_path(pass),
                  fmt::format("expected {}, got {}", expected, cm.channels.size()));
    s.channels.push_back(cm);
  }
}

// The channel a preset needs but the first frame lacks: an error listing what the file has.
[[noreturn]] void missing_channel(const std::string& key, const std::string& first,
                                  const std::vector<std::string>& have, const std::string& ch,
                                  const std::string& what) {
  std::string list;
  for (std::size_t i = 0; i < have.size() && i < 64; ++i)
    list += (i ? ", " : "") + echo(have[i], 40);
  if (have.size() > 64) list += fmt::format(", ... ({} more)", have.size() - 64);
  throw Error(key, fmt::format("channel '{}' ({}) is not in '{}', which has: {}", echo(ch), what,
                               echo_path(first), list.empty() ? "no channels" : list));
}

// The first frame must exist and carry every pass the pipeline may read; it gives the size.
// Returns the channel holding coverage (alpha).
std::string check_first_frame(const Reader& r, pipeline::Source& s, const std::string& first) {
  if (const std::string problem = io::input_file_problem(first, echo_path(first)); !problem.empty())
    throw Error(r.key_path("sequence"), fmt::format("{} (frame {})", problem, s.first_frame));
  const std::vector<std::string> have = io::list_channels(first);
  auto has = [&](const std::string& ch) {
    return std::find(have.begin(), have.end(), ch) != have.end();
  };
  for (const auto& cm : s.channels)
    for (const std::string& ch : cm.channels)
      if (!has(ch))
        missing_channel(r.key_path("channels") + "." + cm.pass, first, have, ch,
                        "pass '" + cm.pass + "'");
  if (s.preset == pipeline::SourcePreset::kBlender) {
    for (const std::string& ch : io::blender_channels(s.view_layer))
      if (!has(ch))
        missing_channel(
            r.key_path("preset"), first, have, ch,
            fmt::format("a pass preset 'blender' reads from view layer '{}'", echo(s.view_layer)));
    return s.view_layer + ".Combined.A";
  }
  for (const render::PassInfo& p : render::pass_table()) {
    bool mapped = false;
    for (const auto& cm : s.channels) mapped = mapped || cm.pass == p.name;
    if (mapped) continue;
    const std::vector<std::string> want = io::source_channels(s, p);
    const auto absent =
        std::find_if(want.begin(), want.end(), [&](const std::string& ch) { return !has(ch); });
    if (absent == want.end()) continue;
    // A single-channel pass as Blender's File Output node names a value socket.
    const std::string value = std::string(p.name) + ".V";
    if (p.count == 1 && has(value)) {
      s.channels.push_back({p.name, {value}});
      continue;
    }
    missing_channel(r.key_path("sequence"), first, have, *absent, fmt::format("pass '{}'", p.name));
  }
  return io::source_channels(s, *render::find_pass("alpha"))[0];
}

void parse_sequence_source(const Reader& r, const PathContext& ctx, pipeline::Source& s) {
  s.kind = pipeline::SourceKind::kSequence;
  const std::string raw = r.string("sequence", "");
  check_pattern(r.key_path("sequence"), raw);
  s.pattern = ctx.resolve(raw);
  s.preset = r.choice("preset", s.preset, kSourcePresets);
  const bool blender = s.preset == pipeline::SourcePreset::kBlender;
  if (r.has("view_layer") && !blender)
    throw Error(r.key_path("view_layer"), "applies to preset = \"blender\" only");
  s.view_layer = r.string("view_layer", s.view_layer);
  for (const char* k : {"normals", "up", "premultiplied"})
    if (r.has(k) && blender)
      throw Error(r.key_path(k),
                  "applies to preset = \"emaki\" only (\"blender\" knows Blender's conventions)");
  s.world_normals = r.choice("normals", s.world_normals, kNormalSpaces);
  s.z_up = r.choice("up", s.z_up, kUpAxes);
  s.premultiplied = r.boolean("premultiplied", s.premultiplied);
  s.passes_colorspace = r.string("passes_colorspace", s.passes_colorspace);
  for (const char* k : {"clip", "start", "loop", "aa", "outline_width", "crease", "camera", "light",
                        "ground", "background", "size", "objects"})
    if (r.has(k)) throw Error(r.key_path(k), "applies to a 'scene' source only");
  parse_channel_mapping(r, s);
  const std::string first = io::frame_file(s.pattern, s.first_frame);
  const std::string alpha_channel = check_first_frame(r, s, first);
  const io::AnyImage probe = io::read_image(first, io::ReadOptions{{alpha_channel}});
  s.width = probe.width();
  s.height = probe.height();
}

}  // namespace

void parse_source(const Reader& r, const PathContext& ctx, pipeline::Source& s) {
  const int given = r.has("scene") + r.has("objects") + r.has("sequence");
  if (given != 1)
    throw Error(r.path(), given ? "give one of 'scene', 'objects' or 'sequence', not several"
                                : "needs 'scene' (a glTF file), 'objects' (glTF assets placed in "
                                  "the shot) or 'sequence' (EXR frames)");
  parse_frames(r, s);
  s.fps = r.real("fps", s.fps);
  if (!r.has("sequence"))
    parse_scene_source(r, ctx, s);
  else
    parse_sequence_source(r, ctx, s);
}

}  // namespace emaki::shot
