#include "io/shot_file.h"

#include <fmt/format.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/limits.h"
#include "io/image_io.h"
#include "io/shot_inputs.h"
#include "io/studio_passes.h"
#include "render/passes.h"

namespace emaki::io {

namespace fs = std::filesystem;
using pipeline::Shot;

int edit_distance(std::string_view a, std::string_view b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = int(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = int(i);
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string closest_key(std::string_view key, const std::vector<std::string>& candidates) {
  std::string best;
  int best_d = 1 << 30;
  for (const std::string& c : candidates) {
    const int d = edit_distance(key, c);
    if (d < best_d) best_d = d, best = c;
  }
  // A typo changes a few letters; beyond a third of the word it is another word.
  const int limit = std::max<int>(2, int(key.size()) / 3);
  return best_d <= limit ? best : std::string();
}

namespace {

const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date/time";
  }
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "'" : ", '") + x + "'";
  return s;
}

// Reads one table against the list of keys it may hold; a key not in that list is an error with
// the closest known key as a suggestion.
class Reader {
 public:
  // Scene units, pixels, degrees and seconds beyond this are typos or attacks, and their
  // squares would overflow a float.
  static constexpr double kMaxMagnitude = 1e9;

  // Unknown keys are reported first: a typo explains the errors that would follow from it.
  Reader(const toml::table& table, std::string path, std::vector<std::string> known)
      : table_(table), path_(std::move(path)), known_(std::move(known)) {
    check_unknown_keys();
  }

  // Keys come from the file: an unknown one may be megabytes long, so it is echoed capped.
  std::string key_path(std::string_view key) const {
    return path_.empty() ? echo(key) : path_ + "." + echo(key);
  }
  const std::string& path() const { return path_; }

  const toml::node* node(std::string_view key) {
    CHECK(std::find(known_.begin(), known_.end(), key) != known_.end());
    return table_.get(key);
  }
  bool has(std::string_view key) { return node(key) != nullptr; }

  [[noreturn]] void type_error(std::string_view key, const toml::node& n, const char* expected) {
    throw Error(key_path(key), fmt::format("expected {}, got {}", expected, type_name(n)));
  }

  // Every number must be finite and, unless a key says otherwise, within +-kMaxMagnitude: inf,
  // nan or 1e300 in a camera value would otherwise render blank frames with exit 0.
  double number(std::string_view key, double fallback, double lo = -kMaxMagnitude,
                double hi = kMaxMagnitude) {
    const toml::node* n = node(key);
    if (!n) return fallback;
    double v;
    if (auto i = n->value_exact<int64_t>())
      v = double(*i);
    else if (auto f = n->value_exact<double>())
      v = *f;
    else
      type_error(key, *n, "a number");
    if (!std::isfinite(v)) throw Error(key_path(key), fmt::format("must be finite, got {}", v));
    check_range(key, v, lo, hi);
    return v;
  }
  float real(std::string_view key, float fallback, double lo = -kMaxMagnitude,
             double hi = kMaxMagnitude) {
    return float(number(key, fallback, lo, hi));
  }
  // An integer in [lo, hi], compared as int64 (a double would round 2^53 + 1).
  int64_t integer64(std::string_view key, int64_t fallback, int64_t lo, int64_t hi) {
    const toml::node* n = node(key);
    if (!n) return fallback;
    auto i = n->value_exact<int64_t>();
    if (!i) type_error(key, *n, "an integer");
    if (*i < lo || *i > hi)
      throw Error(key_path(key), fmt::format("must be in [{}, {}], got {}", lo, hi, *i));
    return *i;
  }
  int integer(std::string_view key, int fallback, int64_t lo = INT32_MIN, int64_t hi = INT32_MAX) {
    return int(integer64(key, fallback, std::max<int64_t>(lo, INT32_MIN),
                         std::min<int64_t>(hi, INT32_MAX)));
  }
  bool boolean(std::string_view key, bool fallback) {
    const toml::node* n = node(key);
    if (!n) return fallback;
    auto b = n->value_exact<bool>();
    if (!b) type_error(key, *n, "true or false");
    return *b;
  }
  std::string string(std::string_view key, const std::string& fallback) {
    const toml::node* n = node(key);
    if (!n) return fallback;
    auto s = n->value_exact<std::string>();
    if (!s) type_error(key, *n, "a string");
    return *s;
  }
  std::string choice(std::string_view key, const std::string& fallback,
                     const std::vector<std::string>& options) {
    const std::string s = string(key, fallback);
    if (std::find(options.begin(), options.end(), s) == options.end()) {
      const std::string near = s.size() > 256 ? std::string() : closest_key(s, options);
      throw Error(key_path(key),
                  fmt::format("'{}' is not one of {}{}", echo(s), join(options),
                              near.empty() ? "" : fmt::format(" — did you mean '{}'?", near)));
    }
    return s;
  }
  // An array of exactly `count` numbers (count < 0: any length >= 1).
  std::vector<float> numbers(std::string_view key, int count) {
    const toml::node* n = node(key);
    CHECK(n != nullptr);
    const toml::array* a = n->as_array();
    const std::string expected = count > 0 ? fmt::format("an array of {} numbers", count)
                                           : std::string("an array of numbers");
    if (!a) type_error(key, *n, expected.c_str());
    std::vector<float> out;
    for (const toml::node& e : *a) {
      if (auto i = e.value_exact<int64_t>())
        out.push_back(float(*i));
      else if (auto f = e.value_exact<double>())
        out.push_back(float(*f));
      else
        throw Error(key_path(key),
                    fmt::format("expected {}, found {} in it", expected, type_name(e)));
      if (!std::isfinite(out.back())) throw Error(key_path(key), "values must be finite");
      if (std::abs(out.back()) > kMaxMagnitude)
        throw Error(key_path(key),
                    fmt::format("values must be within +-{}, got {}", kMaxMagnitude, out.back()));
    }
    if ((count > 0 && int(out.size()) != count) || out.empty())
      throw Error(key_path(key), fmt::format("expected {}, got {} value{}", expected, out.size(),
                                             out.size() == 1 ? "" : "s"));
    return out;
  }
  composite::Color color(std::string_view key, composite::Color fallback) {
    if (!has(key)) return fallback;
    const std::vector<float> c = numbers(key, 3);
    for (float v : c)
      if (!(v >= 0.0f && v <= 1.0f))
        throw Error(key_path(key), fmt::format("colour components must be in [0, 1], got {}", v));
    return {c[0], c[1], c[2]};
  }
  glm::vec3 vec3(std::string_view key, glm::vec3 fallback) {
    if (!has(key)) return fallback;
    const std::vector<float> c = numbers(key, 3);
    return {c[0], c[1], c[2]};
  }
  const toml::table* table(std::string_view key, bool required = false) {
    const toml::node* n = node(key);
    if (!n) {
      if (required) throw Error(key_path(key), "is required");
      return nullptr;
    }
    const toml::table* t = n->as_table();
    if (!t) type_error(key, *n, "a table");
    return t;
  }

  // Every key of the table that emaki does not know is an error.
  void check_unknown_keys() const {
    for (const auto& [k, v] : table_) {
      const std::string key(k.str());
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
      const std::string near = closest_key(key, known_);
      throw Error(key_path(key), near.empty()
                                     ? fmt::format("unknown key (known: {})", join(known_))
                                     : fmt::format("unknown key — did you mean '{}'?", near));
    }
  }

 private:
  void check_range(std::string_view key, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi))
      throw Error(key_path(key), fmt::format("must be in [{}, {}], got {}", lo, hi, v));
  }

  const toml::table& table_;
  std::string path_;
  std::vector<std::string> known_;
};

struct Context {
  fs::path base;  // the shot file's folder
  std::string resolve(const std::string& p) const {
    if (p.empty()) return p;
    const fs::path path(p);
    return (path.is_absolute() ? path : base / path).lexically_normal().string();
  }
  // A path key naming an input file that must exist.
  std::string input_file(Reader& r, std::string_view key, bool required) {
    const std::string raw = r.string(key, "");
    if (raw.empty()) {
      if (required) throw Error(r.key_path(key), "is required");
      return raw;
    }
    const std::string p = resolve(raw);
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      throw Error(r.key_path(key), fmt::format("no such file '{}'", echo(p)));
    return p;
  }
};

std::vector<std::string> pass_names() {
  std::vector<std::string> v;
  for (const auto& p : render::pass_table()) v.push_back(p.name);
  return v;
}

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
      if (width > kMaxFrameWidth)
        throw Error(key, fmt::format("'{}': the frame number's width must be at most {}",
                                     echo(pattern), kMaxFrameWidth));
    }
    if (j >= pattern.size() || pattern[j] != 'd')
      throw Error(key, fmt::format("'{}': only %d or %0Nd may follow '%'", echo(pattern)));
    ++count;
    i = j;
  }
  if (count != 1)
    throw Error(key,
                fmt::format("'{}' must contain exactly one frame number (%04d)", echo(pattern)));
}

// ---- source ----

void parse_camera(Reader& r, scene::CameraSpec& c) {
  const std::string mode = r.choice("mode", "auto", {"auto", "look_at", "gltf"});
  c.mode = mode == "auto"      ? scene::CameraSpec::Mode::kAuto
           : mode == "look_at" ? scene::CameraSpec::Mode::kLookAt
                               : scene::CameraSpec::Mode::kGltf;
  c.position = r.vec3("position", c.position);
  if (r.has("target")) c.target = r.vec3("target", c.target), c.has_target = true;
  c.azimuth_deg = r.real("azimuth", c.azimuth_deg);
  c.elevation_deg = r.real("elevation", c.elevation_deg, -89.0, 89.0);
  c.distance = r.real("distance", c.distance, 0.0, Reader::kMaxMagnitude);
  c.fov_deg = r.real("fov", c.fov_deg, 0.1, 169.0);
  c.orthographic = r.boolean("orthographic", c.orthographic);
  c.ortho_height = r.real("ortho_height", c.ortho_height, 0.0, Reader::kMaxMagnitude);
  c.gltf_node = r.integer("gltf_node", c.gltf_node, -1, INT32_MAX);
  if (c.mode == scene::CameraSpec::Mode::kGltf && c.gltf_node < 0)
    throw Error(r.key_path("gltf_node"), "is required with mode = \"gltf\"");
  c.orbit_deg = r.real("orbit", c.orbit_deg);
  c.dolly = r.real("dolly", c.dolly, 0.01, 100.0);
  c.pan = r.vec3("pan", c.pan);
}

void parse_source(Reader& r, Context& ctx, pipeline::Source& s) {
  const bool has_scene = r.has("scene"), has_sequence = r.has("sequence");
  if (has_scene == has_sequence)
    throw Error(r.path(), has_scene ? "give either 'scene' or 'sequence', not both"
                                    : "needs 'scene' (a glTF file) or 'sequence' (EXR frames)");
  if (!r.has("frames")) throw Error(r.key_path("frames"), "is required ([first, last])");
  {
    const toml::node* n = r.node("frames");
    const toml::array* a = n->as_array();
    if (!a) r.type_error("frames", *n, "[first, last]");
    if (a->size() != 2)
      throw Error(r.key_path("frames"), fmt::format("expected [first, last], got {} value{}",
                                                    a->size(), a->size() == 1 ? "" : "s"));
    // Checked as int64 before narrowing: 4294967297 must not quietly become 1.
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
      throw Error(r.key_path("frames"),
                  fmt::format("[{}, {}] is {} frames; a shot holds at most {}", f[0], f[1],
                              f[1] - f[0] + 1, kMaxFrameCount));
    s.first_frame = int(f[0]);
    s.last_frame = int(f[1]);
  }
  s.fps = r.real("fps", s.fps, 1.0, 240.0);
  if (has_scene) {
    s.kind = pipeline::SourceKind::kScene;
    s.scene_path = ctx.input_file(r, "scene", true);
    if (!r.has("size")) throw Error(r.key_path("size"), "is required ([width, height])");
    const std::vector<float> size = r.numbers("size", 2);
    for (float v : size)
      if (v < 1 || v > 16384 || v != std::floor(v))
        throw Error(r.key_path("size"),
                    fmt::format("width and height must be integers in [1, 16384], got {}", v));
    s.width = int(size[0]);
    s.height = int(size[1]);
    check_pixel_budget(r.key_path("size"), s.width, s.height);
    s.shot.clip = r.string("clip", "");
    s.shot.start_time = r.real("start", 0.0f, 0.0, 1e7);
    s.shot.loop = r.boolean("loop", false);
    s.shot.fps = s.fps;
    s.shot.first_frame = s.first_frame;
    s.shot.last_frame = s.last_frame;
    s.shot.background = r.vec3("background", s.shot.background);
    s.render.width = s.width;
    s.render.height = s.height;
    s.render.aa = r.integer("aa", s.render.aa, 1, 4);
    s.render.outline_width = r.real("outline_width", s.render.outline_width, 0.0, 16.0);
    s.render.crease_deg = r.real("crease", s.render.crease_deg, 0.0, 180.0);
    if (const toml::table* t = r.table("camera")) {
      Reader c(*t, r.key_path("camera"),
               {"mode", "position", "target", "azimuth", "elevation", "distance", "fov",
                "orthographic", "ortho_height", "gltf_node", "orbit", "dolly", "pan"});
      parse_camera(c, s.shot.camera);
    }
    if (const toml::table* t = r.table("light")) {
      Reader l(*t, r.key_path("light"), {"direction", "world", "softness"});
      s.shot.light.direction = l.vec3("direction", s.shot.light.direction);
      if (glm::length(s.shot.light.direction) == 0.0f)
        throw Error(l.key_path("direction"), "must not be [0, 0, 0]");
      s.shot.light.camera_relative = !l.boolean("world", false);
      s.shot.light.softness_deg = l.real("softness", s.shot.light.softness_deg, 0.0, 45.0);
    }
    if (const toml::table* t = r.table("ground")) {
      Reader g(*t, r.key_path("ground"), {"enabled", "size", "height", "color"});
      s.shot.ground.enabled = g.boolean("enabled", true);
      s.shot.ground.size = g.real("size", 0.0f, 0.0, Reader::kMaxMagnitude);
      if (g.has("height"))
        s.shot.ground.height = g.real("height", 0.0f), s.shot.ground.auto_height = false;
      const composite::Color c = g.color("color", {0.8f, 0.8f, 0.8f});
      s.shot.ground.color = {c.r, c.g, c.b};
    }
    for (const char* k : {"channels", "preset", "view_layer", "normals", "up", "premultiplied"})
      if (r.has(k)) throw Error(r.key_path(k), "applies to a 'sequence' source only");
  } else {
    s.kind = pipeline::SourceKind::kSequence;
    const std::string raw = r.string("sequence", "");
    check_pattern(r.key_path("sequence"), raw);
    s.pattern = ctx.resolve(raw);
    s.preset = r.choice("preset", "emaki", {"emaki", "blender"});
    if (r.has("view_layer") && s.preset != "blender")
      throw Error(r.key_path("view_layer"), "applies to preset = \"blender\" only");
    s.view_layer = r.string("view_layer", s.view_layer);
    for (const char* k : {"normals", "up", "premultiplied"})
      if (r.has(k) && s.preset == "blender")
        throw Error(r.key_path(k),
                    "applies to preset = \"emaki\" only (\"blender\" knows "
                    "Blender's conventions)");
    s.world_normals = r.choice("normals", "camera", {"camera", "world"}) == "world";
    s.z_up = r.choice("up", "y", {"y", "z"}) == "z";
    s.premultiplied = r.boolean("premultiplied", false);
    for (const char* k : {"clip", "start", "loop", "aa", "outline_width", "crease", "camera",
                          "light", "ground", "background", "size"})
      if (r.has(k)) throw Error(r.key_path(k), "applies to a 'scene' source only");
    if (const toml::table* t = r.table("channels")) {
      const std::vector<std::string> passes = pass_names();
      Reader m(*t, r.key_path("channels"), passes);
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
    // The first frame must exist and carry every pass the pipeline may read.
    const std::string first = frame_file(s.pattern, s.first_frame);
    std::error_code ec;
    if (!fs::is_regular_file(first, ec))
      throw Error(r.key_path("sequence"),
                  fmt::format("no such file '{}' (frame {})", echo(first), s.first_frame));
    const std::vector<std::string> have = list_channels(first);
    auto has = [&](const std::string& ch) {
      return std::find(have.begin(), have.end(), ch) != have.end();
    };
    auto missing = [&](const std::string& key, const std::string& ch, const std::string& what) {
      std::string list;
      for (std::size_t i = 0; i < have.size() && i < 64; ++i)
        list += (i ? ", " : "") + echo(have[i], 40);
      if (have.size() > 64) list += fmt::format(", ... ({} more)", have.size() - 64);
      throw Error(key, fmt::format("channel '{}' ({}) is not in '{}', which has: {}", echo(ch),
                                   what, echo(first), list.empty() ? "no channels" : list));
    };
    for (const auto& cm : s.channels)
      for (const std::string& ch : cm.channels)
        if (!has(ch)) missing(r.key_path("channels") + "." + cm.pass, ch, "pass '" + cm.pass + "'");
    std::string alpha_channel;
    if (s.preset == "blender") {
      for (const std::string& ch : blender_channels(s.view_layer))
        if (!has(ch))
          missing(r.key_path("preset"), ch,
                  fmt::format("a pass preset 'blender' reads from view layer '{}'",
                              echo(s.view_layer)));
      alpha_channel = s.view_layer + ".Combined.A";
    } else {
      for (const render::PassInfo& p : render::pass_table()) {
        bool mapped = false;
        for (const auto& cm : s.channels) mapped = mapped || cm.pass == p.name;
        if (mapped) continue;
        const std::vector<std::string> want = source_channels(s, p);
        const auto absent =
            std::find_if(want.begin(), want.end(), [&](const std::string& ch) { return !has(ch); });
        if (absent == want.end()) continue;
        // A single-channel pass as Blender's File Output node names a value socket.
        const std::string value = std::string(p.name) + ".V";
        if (p.count == 1 && has(value)) {
          s.channels.push_back({p.name, {value}});
          continue;
        }
        missing(r.key_path("sequence"), *absent, fmt::format("pass '{}'", p.name));
      }
      alpha_channel = source_channels(s, *render::find_pass("alpha"))[0];
    }
    const AnyImage probe = read_image(first, ReadOptions{{alpha_channel}});
    s.width = probe.width();
    s.height = probe.height();
  }
}

// ---- exemplars ----

void parse_exemplar(Reader& r, Context& ctx, pipeline::Exemplar& e) {
  const std::string kind = r.choice("kind", "matcap", {"matcap", "keyframe"});
  e.kind = kind == "matcap" ? pipeline::ExemplarKind::kMatcap : pipeline::ExemplarKind::kKeyframe;
  e.painting = ctx.input_file(r, "painting", true);
  if (e.kind == pipeline::ExemplarKind::kMatcap) {
    for (const char* k : {"passes"})
      if (r.has(k)) throw Error(r.key_path(k), "applies to a 'keyframe' exemplar only");
    exemplar::ReferenceSpec& ref = e.reference;
    if (r.has("sphere")) {
      const std::vector<float> c = r.numbers("sphere", 3);
      if (!(c[2] > 0.0f))
        throw Error(r.key_path("sphere"), fmt::format("radius must be > 0, got {}", c[2]));
      ref.center = {c[0], c[1]};
      ref.radius = c[2];
    }
    ref.elevation_deg = r.real("elevation", ref.elevation_deg, -80.0, 80.0);
    if (r.has("horizon")) ref.horizon_row = r.real("horizon", 0.0f);
    ref.fov_deg = r.real("fov", ref.fov_deg, 1.0, 120.0);
    ref.light.direction = r.vec3("light", ref.light.direction);
    if (glm::length(ref.light.direction) == 0.0f)
      throw Error(r.key_path("light"), "must not be [0, 0, 0]");
    ref.light.softness_deg = r.real("softness", ref.light.softness_deg, 0.0, 45.0);
    ref.ground = r.boolean("ground", ref.ground);
    const composite::Color g = r.color("ground_color", {0.8f, 0.8f, 0.8f});
    ref.ground_color = {g.r, g.g, g.b};
    e.aa = r.integer("aa", e.aa, 1, 4);
  } else {
    for (const char* k : {"sphere", "elevation", "horizon", "fov", "light", "softness", "ground",
                          "ground_color", "aa"})
      if (r.has(k)) throw Error(r.key_path(k), "applies to a 'matcap' exemplar only");
    e.passes = ctx.input_file(r, "passes", true);
  }
}

// ---- layers ----

struct KindDefaults {
  std::vector<pipeline::GuideSpec> guides;
  pipeline::MaskSpec mask;
  composite::LayerLook look;
  float temporal_weight = 1.0f;
};

KindDefaults kind_defaults(const std::string& kind) {
  KindDefaults d;
  if (kind == "base") {
    d.guides = {{"normal", 1.0f}, {"diffuse", 1.0f}};
    d.mask = {pipeline::MaskKind::kCovered, 0.0f, 0.5f};
    d.look.source = composite::ColorSource::kAlbedo;
  } else if (kind == "shadow") {
    d.guides = {{"diffuse", 1.0f}, {"shadow", 1.0f}};
    d.mask = {pipeline::MaskKind::kShadow, 2.0f, 0.5f};
    d.look.flat = {0.55f, 0.52f, 0.7f};
    d.look.blend = composite::BlendMode::kMultiply;
  } else if (kind == "outline") {
    d.guides = {{"outline", 2.0f}, {"normal", 0.5f}};
    d.mask = {pipeline::MaskKind::kLines, 3.0f, 0.1f};
    d.look.flat = {0.08f, 0.06f, 0.06f};
    d.look.alpha_from = composite::AlphaFrom::kInverseValue;
    d.temporal_weight = 0.5f;
  }
  return d;
}

composite::BlendMode parse_blend(const std::string& s) {
  if (s == "multiply") return composite::BlendMode::kMultiply;
  if (s == "screen") return composite::BlendMode::kScreen;
  if (s == "overlay") return composite::BlendMode::kOverlay;
  return composite::BlendMode::kNormal;
}

void parse_layer(Reader& r, const Shot& shot, pipeline::Layer& l) {
  l.kind = r.choice("kind", "custom", {"base", "outline", "shadow", "custom"});
  const KindDefaults d = kind_defaults(l.kind);
  l.exemplar = r.string("exemplar", "");
  if (l.exemplar.empty())
    throw Error(r.key_path("exemplar"), "is required (an [exemplars.NAME] table)");
  if (!shot.find_exemplar(l.exemplar)) {
    std::vector<std::string> names;
    for (const auto& e : shot.exemplars) names.push_back(e.name);
    const std::string near = closest_key(l.exemplar, names);
    throw Error(
        r.key_path("exemplar"),
        fmt::format("'{}' is not defined in [exemplars]{}", echo(l.exemplar),
                    near.empty() ? (names.empty() ? std::string(" (there are none)")
                                                  : fmt::format(" (defined: {})", join(names)))
                                 : fmt::format(" — did you mean '{}'?", near)));
  }
  l.guides = d.guides;
  if (const toml::table* t = r.table("guides")) {
    const std::vector<std::string> passes = pass_names();
    Reader g(*t, r.key_path("guides"), passes);
    l.guides.clear();
    // Guides keep the file's order so that results do not depend on how toml++ sorts keys.
    // (line, column): as int64, since a 1 MB file may hold a million lines.
    std::vector<std::pair<std::string, int64_t>> order;
    for (const auto& [k, v] : *t)
      order.emplace_back(std::string(k.str()), int64_t(v.source().begin.line) * 100000000 +
                                                   int64_t(v.source().begin.column));
    std::stable_sort(order.begin(), order.end(),
                     [](auto& a, auto& b) { return a.second < b.second; });
    for (const auto& [pass, line] : order) {
      if (pass == "motion" || pass == "alpha" || pass == "position" || pass == "depth")
        throw Error(g.key_path(pass),
                    "this pass does not mean the same on the exemplar and the shot; "
                    "use normal, diffuse, shadow, outline, albedo, ...");
      l.guides.push_back({pass, g.real(pass, 1.0f, 0.0, 1000.0)});
    }
    if (l.guides.empty()) throw Error(r.key_path("guides"), "needs at least one pass");
  }
  if (l.guides.empty()) throw Error(r.key_path("guides"), "is required for a 'custom' layer");
  pipeline::SynthSpec& s = l.synth;
  s.patch_size = r.integer("patch_size", s.patch_size, 3, 31);
  if (s.patch_size % 2 == 0)
    throw Error(r.key_path("patch_size"), fmt::format("must be odd, got {}", s.patch_size));
  s.uniformity = r.real("uniformity", s.uniformity, 0.0, 1e6);
  s.pyramid_levels = r.integer("pyramid_levels", s.pyramid_levels, -1, 32);
  if (s.pyramid_levels == 0)
    throw Error(r.key_path("pyramid_levels"), "must be >= 1, or -1 for automatic");
  s.search_vote_iters = r.integer("search_vote_iters", s.search_vote_iters, -1, 100);
  s.patch_match_iters = r.integer("patch_match_iters", s.patch_match_iters, -1, 100);
  s.seed = uint64_t(r.integer("seed", 1, 0, INT32_MAX));
  l.single_colour = r.boolean("single_colour", true);
  const std::string channel = r.choice("channel", "luminance", {"luminance", "r", "g", "b"});
  l.channel = channel == "luminance" ? -1 : channel == "r" ? 0 : channel == "g" ? 1 : 2;
  l.temporal.enabled = r.boolean("temporal", true);
  l.temporal.weight = r.real("temporal_weight", d.temporal_weight, 0.0, 1000.0);
  const std::string adv = r.choice("advection", "rest_position", {"position", "rest_position"});
  l.temporal.guide = adv == "position" ? pipeline::AdvectionGuide::kPosition
                                       : pipeline::AdvectionGuide::kRestPosition;
  l.mask = d.mask;
  const std::string mask = r.choice("mask",
                                    d.mask.kind == pipeline::MaskKind::kLines     ? "lines"
                                    : d.mask.kind == pipeline::MaskKind::kShadow  ? "shadow"
                                    : d.mask.kind == pipeline::MaskKind::kCovered ? "covered"
                                                                                  : "none",
                                    {"none", "covered", "objects", "lines", "shadow", "lit"});
  l.mask.kind = mask == "none"      ? pipeline::MaskKind::kNone
                : mask == "covered" ? pipeline::MaskKind::kCovered
                : mask == "objects" ? pipeline::MaskKind::kObjects
                : mask == "lines"   ? pipeline::MaskKind::kLines
                : mask == "shadow"  ? pipeline::MaskKind::kShadow
                                    : pipeline::MaskKind::kLit;
  l.mask.dilate = r.real("mask_dilate", l.mask.dilate, 0.0, 64.0);
  l.mask.threshold = r.real("mask_threshold", l.mask.threshold, 0.0, 1.0);
  l.order = r.integer("order", 0);

  composite::LayerLook& look = l.look;
  look = d.look;
  if (const toml::node* n = r.node("color")) {
    if (n->is_string()) {
      const std::string c = r.choice("color", "albedo", {"albedo", "gradient"});
      look.source =
          c == "albedo" ? composite::ColorSource::kAlbedo : composite::ColorSource::kGradient;
    } else if (n->is_array()) {
      look.source = composite::ColorSource::kFlat;
      look.flat = r.color("color", look.flat);
    } else {
      r.type_error("color", *n, "\"albedo\", \"gradient\" or [r, g, b]");
    }
  }
  if (const toml::node* n = r.node("gradient")) {
    const toml::array* a = n->as_array();
    const char* expected = "an array of [position, r, g, b] stops";
    if (!a) r.type_error("gradient", *n, expected);
    look.gradient.clear();
    for (const toml::node& stop : *a) {
      const toml::array* sa = stop.as_array();
      std::vector<float> v;
      if (sa)
        for (const toml::node& e : *sa) {
          if (auto i = e.value_exact<int64_t>())
            v.push_back(float(*i));
          else if (auto f = e.value_exact<double>())
            v.push_back(float(*f));
        }
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
  if (look.source == composite::ColorSource::kGradient && look.gradient.empty())
    throw Error(r.key_path("gradient"), "is required with color = \"gradient\"");
  const std::string alpha =
      r.choice("alpha",
               look.alpha_from == composite::AlphaFrom::kInverseValue ? "inverse_value"
               : look.alpha_from == composite::AlphaFrom::kValue      ? "value"
                                                                      : "mask",
               {"mask", "value", "inverse_value"});
  look.alpha_from = alpha == "mask"    ? composite::AlphaFrom::kMask
                    : alpha == "value" ? composite::AlphaFrom::kValue
                                       : composite::AlphaFrom::kInverseValue;
  const std::string blend_default =
      look.blend == composite::BlendMode::kMultiply ? "multiply" : "normal";
  look.blend =
      parse_blend(r.choice("blend", blend_default, {"normal", "multiply", "screen", "overlay"}));
  composite::Filters& f = look.filters;
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
  f.hue_deg = r.real("hue", 0.0f, -360.0, 360.0);
  f.saturation = r.real("saturation", 1.0f, 0.0, 10.0);
  f.opacity = r.real("opacity", 1.0f, 0.0, 1.0);
}

void check_output_folder(const std::string& key, const std::string& folder) {
  std::error_code ec;
  fs::path p(folder);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec))
      throw Error(key, fmt::format("'{}' exists and is not a folder", echo(folder)));
    if (::access(p.c_str(), W_OK | X_OK) != 0)
      throw Error(key, fmt::format("folder '{}' is not writable", echo(folder)));
    return;
  }
  // Not there yet: the nearest existing parent must let us create it.
  fs::path parent = p.parent_path();
  while (!parent.empty() && !fs::exists(parent, ec)) parent = parent.parent_path();
  if (parent.empty()) parent = ".";
  if (!fs::is_directory(parent, ec) || ::access(parent.c_str(), W_OK | X_OK) != 0)
    throw Error(key, fmt::format("cannot create folder '{}': '{}' is not a writable folder",
                                 echo(folder), echo(parent.string())));
}

int declared_line(const toml::node& n) {
  return int(n.source().begin.line);
}

// toml++ recurses once per level of dotted key, table header, inline table and array (and so
// does destroying the tree): a 400 KB file of `a.a.a...= 1` overflows the stack. This cheap
// scan bounds the depth first. Depth here is 1 + open [ and { + the dots of the key being read;
// strings and comments are skipped, and the dot count restarts at every = , newline or bracket,
// so the dot of a float (1.5) adds one level at most.
void check_nesting(std::string_view text, const std::string& path) {
  int brackets = 0, dots = 0, line = 1;
  auto too_deep = [&] {
    throw Error(path, fmt::format("line {}: nested deeper than {} levels (tables, arrays, inline "
                                  "tables or dotted keys)",
                                  line, kMaxShotDepth));
  };
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    switch (c) {
      case '\n':
        ++line;
        dots = 0;
        break;
      case '#':
        while (i + 1 < n && text[i + 1] != '\n') ++i;
        break;
      case '"':
      case '\'': {
        const bool basic = c == '"';
        const bool multi = i + 2 < n && text[i + 1] == c && text[i + 2] == c;
        i += multi ? 3 : 1;
        for (; i < n; ++i) {
          if (text[i] == '\n') {
            ++line;
            if (!multi) break;  // unterminated: toml++ reports it
          }
          if (basic && text[i] == '\\') {
            if (i + 1 < n && text[i + 1] == '\n') ++line;
            ++i;
            continue;
          }
          if (text[i] != c) continue;
          if (!multi) break;
          if (i + 2 < n && text[i + 1] == c && text[i + 2] == c) {
            // Up to two more quotes may close a multi-line string ("""a"""").
            i += 2;
            while (i + 1 < n && text[i + 1] == c) ++i;
            break;
          }
        }
        break;
      }
      case '[':
      case '{':
        if (++brackets + dots + 1 > kMaxShotDepth) too_deep();
        dots = 0;
        break;
      case ']':
      case '}':
        brackets = std::max(0, brackets - 1);
        dots = 0;
        break;
      case '=':
      case ',':
        dots = 0;
        break;
      case '.':
        if (brackets + ++dots + 1 > kMaxShotDepth) too_deep();
        break;
      default:
        break;
    }
  }
}

}  // namespace

Shot parse_shot(std::string_view text, const std::string& path) {
  if (text.size() > kMaxShotBytes)
    throw Error(path, fmt::format("is {} bytes; a shot file may hold at most {}", text.size(),
                                  kMaxShotBytes));
  check_nesting(text, path);
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(path));
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw Error(fmt::format("{}:{}:{}", path, b.line, b.column), std::string(e.description()));
  }
  Shot shot;
  shot.path = path;
  Context ctx{fs::path(path).parent_path()};
  Reader top(root, "",
             {"source", "exemplars", "layers", "compositing", "outputs", "threads", "limits"});
  shot.threads = top.integer("threads", 0, 0, 1024);
  // First: the budget applies to source.size and to the sequence's first frame read below.
  if (const toml::table* t = top.table("limits")) {
    Reader r(*t, "limits", {"max_pixels"});
    if (r.has("max_pixels")) {
      set_max_pixels_from_file(r.integer64("max_pixels", 0, 1, int64_t(1) << 40));
    }
  }

  {
    Reader src(*top.table("source", true), "source",
               {"scene",   "sequence", "frames",       "size",          "fps",    "clip",
                "start",   "loop",     "aa",           "outline_width", "crease", "camera",
                "light",   "ground",   "background",   "channels",      "preset", "view_layer",
                "normals", "up",       "premultiplied"});
    parse_source(src, ctx, shot.source);
  }

  const toml::table* exemplars = top.table("exemplars", true);
  {
    std::vector<std::pair<int, std::string>> names;
    for (const auto& [k, v] : *exemplars)
      names.emplace_back(declared_line(v), std::string(k.str()));
    std::sort(names.begin(), names.end());
    for (const auto& [line, name] : names) {
      const toml::node* n = exemplars->get(name);
      const std::string key = "exemplars." + echo(name);
      if (!n->is_table()) throw Error(key, fmt::format("expected a table, got {}", type_name(*n)));
      Reader r(*n->as_table(), key,
               {"kind", "painting", "sphere", "elevation", "horizon", "fov", "light", "softness",
                "ground", "ground_color", "aa", "passes"});
      pipeline::Exemplar e;
      e.name = name;
      parse_exemplar(r, ctx, e);
      shot.exemplars.push_back(std::move(e));
    }
    if (shot.exemplars.empty())
      throw Error("exemplars", "needs at least one [exemplars.NAME] table");
  }

  const toml::table* layers = top.table("layers", true);
  {
    std::vector<std::pair<int, std::string>> names;
    for (const auto& [k, v] : *layers) names.emplace_back(declared_line(v), std::string(k.str()));
    std::sort(names.begin(), names.end());
    for (const auto& [line, name] : names) {
      const toml::node* n = layers->get(name);
      const std::string key = "layers." + echo(name);
      if (!n->is_table()) throw Error(key, fmt::format("expected a table, got {}", type_name(*n)));
      for (char c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
          throw Error(key,
                      "layer names may use letters, digits, '_' and '-' only (they name files)");
      Reader r(*n->as_table(), key,
               {"kind",
                "exemplar",
                "guides",
                "patch_size",
                "uniformity",
                "pyramid_levels",
                "search_vote_iters",
                "patch_match_iters",
                "seed",
                "single_colour",
                "channel",
                "temporal",
                "temporal_weight",
                "advection",
                "mask",
                "mask_dilate",
                "mask_threshold",
                "order",
                "color",
                "gradient",
                "alpha",
                "blend",
                "levels",
                "output_levels",
                "tint",
                "hue",
                "saturation",
                "opacity"});
      pipeline::Layer l;
      l.name = name;
      parse_layer(r, shot, l);
      shot.layers.push_back(std::move(l));
    }
    if (shot.layers.empty()) throw Error("layers", "needs at least one [layers.NAME] table");
    std::stable_sort(shot.layers.begin(), shot.layers.end(),
                     [](const auto& a, const auto& b) { return a.order < b.order; });
  }

  if (const toml::table* t = top.table("compositing")) {
    Reader r(*t, "compositing", {"paper", "paper_scale", "paper_color"});
    shot.compositing.paper = ctx.input_file(r, "paper", false);
    shot.compositing.paper_scale = r.real("paper_scale", 1.0f, 0.01, 100.0);
    shot.compositing.paper_color = r.color("paper_color", shot.compositing.paper_color);
  }

  {
    const toml::table* t = top.table("outputs", true);
    Reader r(*t, "outputs",
             {"folder", "layer_png", "composite_png", "composite_exr", "layered_exr", "mp4",
              "contact_sheet", "crf"});
    pipeline::Outputs& o = shot.outputs;
    const std::string folder = r.string("folder", "");
    if (folder.empty()) throw Error("outputs.folder", "is required");
    o.folder = ctx.resolve(folder);
    o.layer_png = r.boolean("layer_png", o.layer_png);
    o.composite_png = r.boolean("composite_png", o.composite_png);
    o.composite_exr = r.boolean("composite_exr", o.composite_exr);
    o.layered_exr = r.boolean("layered_exr", o.layered_exr);
    o.mp4 = r.boolean("mp4", o.mp4);
    o.contact_sheet = r.boolean("contact_sheet", o.contact_sheet);
    o.crf = r.integer("crf", o.crf, 0, 51);
    if (o.mp4 && !o.composite_png)
      throw Error("outputs.mp4",
                  "is made from the composited PNG frames: needs composite_png = true");
    check_output_folder("outputs.folder", o.folder);
  }
  return shot;
}

Shot load_shot(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "cannot open the shot file");
  // Read at most one byte past the cap: a huge file (or /dev/zero) is refused without reading it.
  std::string text(kMaxShotBytes + 1, '\0');
  in.read(text.data(), std::streamsize(text.size()));
  if (in.bad()) throw Error(path, "cannot read the shot file");
  text.resize(std::size_t(in.gcount()));
  if (text.size() > kMaxShotBytes)
    throw Error(
        path, fmt::format("is larger than {} bytes, the most a shot file may hold", kMaxShotBytes));
  return parse_shot(text, path);
}

}  // namespace emaki::io
