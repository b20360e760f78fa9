// The shot file's top level: size and nesting bounds, TOML syntax, the sections in order, and
// the output folder.
#include "shot/parser.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <tuple>

#include "colour/colour.h"
#include "core/shot_keys.h"
#include "io/input_file.h"
#include "shot/parser_sections.h"

namespace emaki::shot {

namespace fs = std::filesystem;
using pipeline::Shot;

namespace {

void check_output_folder(const std::string& key, const std::string& folder) {
  std::error_code ec;
  fs::path p(folder);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec))
      throw Error(key, fmt::format("'{}' exists and is not a folder", echo_path(folder)));
    if (::access(p.c_str(), W_OK | X_OK) != 0)
      throw Error(key, fmt::format("folder '{}' is not writable", echo_path(folder)));
    return;
  }
  // Not there yet: the nearest existing parent must let us create it.
  fs::path parent = p.parent_path();
  while (!parent.empty() && !fs::exists(parent, ec)) parent = parent.parent_path();
  if (parent.empty()) parent = ".";
  if (!fs::is_directory(parent, ec) || ::access(parent.c_str(), W_OK | X_OK) != 0)
    throw Error(key, fmt::format("cannot create folder '{}': '{}' is not a writable folder",
                                 echo_path(folder), echo_path(parent.string())));
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

// One [exemplars.NAME] or [layers.NAME] table after another, in the file's order.
std::vector<std::pair<int, std::string>> names_in_file_order(const toml::table& t) {
  std::vector<std::pair<int, std::string>> names;
  for (const auto& [k, v] : t) names.emplace_back(declared_line(v), std::string(k.str()));
  std::sort(names.begin(), names.end());
  return names;
}

const toml::table& subtable(const toml::table& parent, const std::string& name,
                            const std::string& key) {
  const toml::node* n = parent.get(name);
  if (!n->is_table()) throw Error(key, fmt::format("expected a table, got {}", type_name(*n)));
  return *n->as_table();
}

void parse_exemplars(const toml::table& exemplars, const PathContext& ctx, Shot& shot) {
  for (const auto& [line, name] : names_in_file_order(exemplars)) {
    const std::string key = "exemplars." + echo(name);
    const Reader r(subtable(exemplars, name, key), key, "exemplars.NAME");
    pipeline::Exemplar e;
    e.name = name;
    parse_exemplar(r, ctx, e);
    shot.exemplars.push_back(std::move(e));
  }
  if (shot.exemplars.empty()) throw Error("exemplars", "needs at least one [exemplars.NAME] table");
}

void parse_layers(const toml::table& layers, Shot& shot) {
  for (const auto& [line, name] : names_in_file_order(layers)) {
    const std::string key = "layers." + echo(name);
    if (name.empty())
      throw Error("layers.\"\"",
                  "a layer needs a name (letters, digits, '_' and '-'; it names files)");
    const toml::table& t = subtable(layers, name, key);
    for (char c : name)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'))
        throw Error(key, "layer names may use letters, digits, '_' and '-' only (they name files)");
    const Reader r(t, key, "layers.NAME");
    pipeline::Layer l;
    l.name = name;
    parse_layer(r, shot, l);
    shot.layers.push_back(std::move(l));
  }
  if (shot.layers.empty()) throw Error("layers", "needs at least one [layers.NAME] table");
  std::stable_sort(shot.layers.begin(), shot.layers.end(),
                   [](const auto& a, const auto& b) { return a.order < b.order; });
}

void parse_outputs(const Reader& r, const PathContext& ctx, Shot& shot) {
  pipeline::Outputs& o = shot.outputs;
  const std::string folder = r.string("folder", "");
  if (folder.empty()) throw Error("outputs.folder", "is required");
  o.folder = ctx.resolve(folder);
  // Which files are written: each key switches one member.
  using Switch = std::pair<const char*, bool pipeline::Outputs::*>;
  for (const auto& [key, member] : {Switch{"layer_png", &pipeline::Outputs::layer_png},
                                    Switch{"composite_png", &pipeline::Outputs::composite_png},
                                    Switch{"composite_exr", &pipeline::Outputs::composite_exr},
                                    Switch{"layered_exr", &pipeline::Outputs::layered_exr},
                                    Switch{"mp4", &pipeline::Outputs::mp4},
                                    Switch{"contact_sheet", &pipeline::Outputs::contact_sheet}})
    o.*member = r.boolean(key, o.*member);
  o.crf = r.integer("crf", o.crf);
  shot.colour.display = r.string("display", shot.colour.display);
  shot.colour.view = r.string("view", shot.colour.view);
  if (o.mp4 && !o.composite_png)
    throw Error("outputs.mp4",
                "is made from the composited PNG frames: needs composite_png = true");
  check_output_folder("outputs.folder", o.folder);
}

// The config opened and every colour-space, display and view name of the shot looked up in it,
// before any frame runs; the display and view defaults filled in.
void check_colour(Shot& shot) {
  shot.colour.ocio = colour::Config::open(shot.colour.config, shot_keys::kColourConfig);
  const colour::Config& c = *shot.colour.ocio;
  for (const pipeline::Exemplar& e : shot.exemplars)
    c.require_space(shot_keys::exemplar_key(echo(e.name), shot_keys::kColorspace), e.colorspace);
  c.require_space(shot_keys::kPaperColorspace, shot.compositing.paper_colorspace);
  if (shot.source.kind == pipeline::SourceKind::kSequence)
    c.require_space(shot_keys::kPassesColorspace, shot.source.passes_colorspace);
  // The working spaces are roles: a config without them cannot composite.
  c.require_space(shot_keys::kCompositingSpace, "color_picking");
  if (shot.compositing.space == pipeline::CompositingSpace::kSceneLinear)
    c.require_space(shot_keys::kCompositingSpace, "scene_linear");
  std::tie(shot.colour.display, shot.colour.view) = c.require_display_view(
      shot_keys::kOutputsDisplay, shot.colour.display, shot_keys::kOutputsView, shot.colour.view);
}

toml::table parse_toml(std::string_view text, const std::string& path) {
  if (text.size() > kMaxShotBytes)
    throw Error(path, fmt::format("is {} bytes; a shot file may hold at most {}", text.size(),
                                  kMaxShotBytes));
  check_nesting(text, path);
  try {
    return toml::parse(text, std::string_view(path));
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw Error(fmt::format("{}:{}:{}", path, b.line, b.column), std::string(e.description()));
  }
}

}  // namespace

Shot parse_shot(std::string_view text, const std::string& path) {
  const toml::table root = parse_toml(text, path);
  Shot shot;
  shot.path = path;
  const PathContext ctx{fs::path(path).parent_path()};
  const Reader top(root, "", "");
  shot.threads = top.integer("threads", shot.threads);
  // First: the budget applies to source.size and to the sequence's first frame read below.
  if (const toml::table* t = top.table("limits")) {
    const Reader r(*t, "limits", "limits");
    if (r.has("max_pixels")) shot.max_pixels = r.integer64("max_pixels", 0);
  }
  const ScopedMaxPixels budget(shot_max_pixels(shot.max_pixels));
  if (const toml::table* t = top.table("colour")) {
    const Reader r(*t, "colour", "colour");
    shot.colour.config = ctx.input_file(r, "config", false);
  }
  parse_source(Reader(*top.table("source", true), "source", "source"), ctx, shot.source);
  parse_exemplars(*top.table("exemplars", true), ctx, shot);
  parse_layers(*top.table("layers", true), shot);
  if (const toml::table* t = top.table("compositing")) {
    const Reader r(*t, "compositing", "compositing");
    shot.compositing.paper = ctx.input_file(r, "paper", false);
    shot.compositing.paper_scale = r.real("paper_scale", shot.compositing.paper_scale);
    shot.compositing.paper_color = r.color("paper_color", shot.compositing.paper_color);
    shot.compositing.paper_colorspace =
        r.string("paper_colorspace", shot.compositing.paper_colorspace);
    shot.compositing.space = r.choice("space", shot.compositing.space, kCompositingSpaces);
  }
  parse_outputs(Reader(*top.table("outputs", true), "outputs", "outputs"), ctx, shot);
  check_colour(shot);
  return shot;
}

Shot load_shot(const std::string& path) {
  // Checked before opening: opening a FIFO waits for a writer.
  if (const std::string problem = io::input_file_problem(path); !problem.empty())
    throw Error(path, problem);
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

}  // namespace emaki::shot
