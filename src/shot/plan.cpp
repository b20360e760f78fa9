#include "shot/plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <unordered_map>

#include "core/error.h"
#include "core/fnv.h"
#include "core/limits.h"
#include "core/utf8.h"
#include "io/image_io.h"
#include "shot/api.h"
#include "shot/objects.h"
#include "store/file_store.h"

namespace emaki::shot {

namespace fs = std::filesystem;

const char* task_kind_name(TaskKind kind) {
  switch (kind) {
    case TaskKind::kPrepare:
      return "prepare";
    case TaskKind::kPasses:
      return "passes";
    case TaskKind::kLayer:
      return "layer";
    case TaskKind::kComposite:
      return "composite";
    case TaskKind::kPreviews:
      return "previews";
  }
  return "?";
}

namespace {

// What a task holds of a scene source: the opened scene (shot/objects.h) in every task that
// opens it, and, in the passes task that renders it, the posed geometry of a frame (about 250
// bytes a drawn vertex and 200 a drawn triangle, io/gltf_loader.h).
double scene_mb(const SceneCost& scene, TaskKind kind) {
  if (kind == TaskKind::kPreviews) return 0;
  double bytes = double(scene.bytes);
  if (kind == TaskKind::kPasses)
    bytes += 250.0 * double(scene.drawn_vertices) + 200.0 * double(scene.drawn_triangles);
  return bytes / 1e6;
}

// The scene opened as every task opens it. One that does not open (a broken file, a scene over
// its budget) costs nothing here: the shot's prepare task fails on it with the error, and the
// other shots of the plan still run.
SceneCost scene_cost(const pipeline::Shot& s) {
  SceneCost cost;
  if (s.source.kind != pipeline::SourceKind::kScene) return cost;
  try {
    (void)load_scene(s.source, &cost);
  } catch (const Error&) {
    return {};
  }
  return cost;
}

}  // namespace

// Peak resident memory of a task in MB, from the frame size, the exemplars' sizes and the scene.
// The constants are peak RSS per pixel measured with /usr/bin/time on `emaki task` at 160x90,
// 480x270 and 960x540 with the StyLit exemplar (docs/farm.md), plus a quarter for margin.
int64_t task_memory_mb(const pipeline::Shot& s, double exemplar_pixels, TaskKind kind,
                       const SceneCost& scene) {
  const double px = double(s.source.width) * s.source.height;
  const double aa = s.source.kind == pipeline::SourceKind::kScene ? s.source.render.aa : 1;
  double mb = 0;
  switch (kind) {
    case TaskKind::kPrepare:
      mb = 60 + (exemplar_pixels * 360 + px * 100) / 1e6;
      break;
    case TaskKind::kPasses:
      mb = 170 + px * aa * aa * 50 / 1e6;
      break;
    case TaskKind::kLayer:
      mb = 60 + (exemplar_pixels * 330 + px * 300) / 1e6;
      break;
    case TaskKind::kComposite:
      mb = 150 + px * 550 / 1e6;
      break;
    case TaskKind::kPreviews:
      mb = 60 + px * 60 / 1e6;
      break;
  }
  mb += scene_mb(scene, kind);
  const int64_t with_margin = int64_t(mb * 1.25) + 1;
  return (with_margin + 63) / 64 * 64;
}

namespace {

// The exemplars' painting pixels (they dominate a small shot's memory).
double exemplar_pixels(const pipeline::Shot& s) {
  double px = 0;
  for (const pipeline::Exemplar& e : s.exemplars) {
    const io::AnyImage img = io::read_image(e.painting);
    px += double(img.width()) * img.height();
  }
  return px;
}

// A shot's name in task ids: the file's stem, readable, and a digest (FNV-1a, 32 bits shown) of
// its canonical path, so that d1/a.toml, d2/a.toml and a-2.toml differ and a shot keeps its ids
// whichever other shots are planned beside it.
std::string shot_name(const std::string& path) {
  std::error_code ec;
  fs::path canonical = fs::weakly_canonical(path, ec);
  if (ec) canonical = fs::absolute(path).lexically_normal();
  const uint64_t h = fnv1a(canonical.string());
  return fmt::format("{}-{:08x}", fs::path(path).stem().string(), uint32_t(h ^ (h >> 32)));
}

std::string frames_text(int a, int b) {
  return fmt::format("{}-{}", a, b);
}

class Planner {
 public:
  Planner(Plan& plan, const PlanOptions& o) : plan_(plan), o_(o) {}

  void add_shot(int index) {
    const PlannedShot& ps = plan_.shots[std::size_t(index)];
    const pipeline::Shot& s = ps.shot;
    const ScopedMaxPixels budget(shot_max_pixels(s.max_pixels));
    const io::FileStore state(s, io::StoreMode::kRun, io::StoreAccess::kInspect);
    const std::string& out = s.outputs.folder;
    const int first = s.source.first_frame, last = s.source.last_frame;
    exemplar_pixels_ = exemplar_pixels(s);
    shot_tasks_ = plan_.tasks.size();
    scene_ = scene_cost(s);

    const bool scene = s.source.kind == pipeline::SourceKind::kScene;
    // Each task is done when its own outputs are there under current manifests (what `emaki run`
    // resumes from): a shot run on one machine has no pass cache, and needs none.
    auto passes_done = [&](int a, int b) {
      for (int f = a; f <= b; ++f)
        if (!state.has_passes(f) && !finished(s, state, f)) return false;
      return true;
    };
    const bool need_cache = scene && !passes_done(first, last);
    const std::string prepare =
        add(index, TaskKind::kPrepare, "", first, last, {out}, {}, state.prepared(need_cache));
    // A chunked task waits only for the tasks that make its own frames (chunks of every stage
    // start at `first` and step by the chunk, so they line up); a temporal layer's task, which
    // covers the shot, waits for every chunk. So the graph has O(frames / chunk) edges.
    std::vector<std::string> passes;
    if (scene)
      for (int a = first; a <= last; a += o_.chunk) {
        const int b = std::min(last, a + o_.chunk - 1);
        passes.push_back(add(index, TaskKind::kPasses, "", a, b, {out + "/passes"}, {prepare},
                             passes_done(a, b)));
      }
    const auto passes_of = [&](int chunk) {
      return scene ? std::vector{passes[std::size_t(chunk)]} : std::vector{prepare};
    };
    std::vector<std::string> whole_layers;               // temporal: one task each
    std::vector<std::vector<std::string>> chunk_layers(  // per chunk: the chunked layers' tasks
        std::size_t((last - first) / o_.chunk + 1));
    for (const pipeline::Layer& l : s.layers) {
      const bool whole = l.temporal.enabled;
      const int step = whole ? last - first + 1 : o_.chunk;
      for (int a = first; a <= last; a += step) {
        const int b = std::min(last, a + step - 1);
        bool done = true;
        for (int f = a; f <= b && done; ++f) done = state.has_layer(l, f);
        const int chunk = (a - first) / o_.chunk;
        const std::string id =
            add(index, TaskKind::kLayer, l.name, a, b, {out + "/layers/" + l.name},
                whole ? (scene ? passes : std::vector{prepare}) : passes_of(chunk), done);
        (whole ? whole_layers : chunk_layers[std::size_t(chunk)]).push_back(id);
      }
    }
    std::vector<std::string> composites;
    for (int a = first; a <= last; a += o_.chunk) {
      const int b = std::min(last, a + o_.chunk - 1);
      bool done = true;
      for (int f = a; f <= b && done; ++f) done = state.has_frame(f);
      std::vector<std::string> after = passes_of((a - first) / o_.chunk);
      after.insert(after.end(), whole_layers.begin(), whole_layers.end());
      const std::vector<std::string>& chunked = chunk_layers[std::size_t((a - first) / o_.chunk)];
      after.insert(after.end(), chunked.begin(), chunked.end());
      composites.push_back(add(index, TaskKind::kComposite, "", a, b,
                               {out + "/composite", out + "/layered"}, after, done));
    }
    // Previews are cheap and are remade whenever anything else is.
    bool all_done = true;
    for (std::size_t i = shot_tasks_; i < plan_.tasks.size(); ++i)
      all_done = all_done && plan_.tasks[i].done;
    add(index, TaskKind::kPreviews, "", first, last, {out}, composites,
        all_done && previews_exist(s));
  }

 private:
  // Every output of frame `f` is there: its passes are needed by no task.
  static bool finished(const pipeline::Shot& s, const io::FileStore& state, int f) {
    for (const pipeline::Layer& l : s.layers)
      if (!state.has_layer(l, f)) return false;
    return state.has_frame(f);
  }

  static bool previews_exist(const pipeline::Shot& s) {
    const io::OutputPaths paths{s.outputs.folder};
    std::error_code ec;
    if (s.outputs.contact_sheet && !fs::is_regular_file(paths.contact_sheet(), ec)) return false;
    if (s.outputs.mp4 && !fs::is_regular_file(paths.mp4(), ec)) return false;
    return true;
  }

  std::string add(int shot, TaskKind kind, const std::string& layer, int a, int b,
                  std::vector<std::string> outputs, const std::vector<std::string>& after,
                  bool done) {
    const PlannedShot& ps = plan_.shots[std::size_t(shot)];
    Task t;
    t.shot = shot;
    t.kind = kind;
    t.layer = layer;
    t.first_frame = a;
    t.last_frame = b;
    t.id = fmt::format("{}.{}", ps.name, task_kind_name(kind));
    if (!layer.empty()) t.id += fmt::format(".{}", layer);
    if (kind == TaskKind::kPasses || kind == TaskKind::kLayer || kind == TaskKind::kComposite)
      t.id += fmt::format(".{}", frames_text(a, b));
    // A path or layer name starting with '-' would read as an option of `emaki task`.
    t.argv = {o_.emaki, "task", task_kind_name(kind),
              ps.path.starts_with('-') ? "./" + ps.path : ps.path};
    if (layer.starts_with('-'))
      t.argv.push_back("--layer=" + layer);
    else if (!layer.empty())
      t.argv.insert(t.argv.end(), {"--layer", layer});
    if (kind != TaskKind::kPrepare && kind != TaskKind::kPreviews)
      t.argv.insert(t.argv.end(), {"--frames", frames_text(a, b)});
    t.threads = o_.threads;
    t.argv.insert(t.argv.end(), {"--threads", std::to_string(o_.threads)});
    t.outputs = std::move(outputs);
    t.memory_mb = task_memory_mb(ps.shot, exemplar_pixels_, kind, scene_);
    t.done = done;
    for (const std::string& id : after)
      if (!done_.at(id)) t.after.push_back(id);
    done_[t.id] = t.done;
    plan_.tasks.push_back(std::move(t));
    return plan_.tasks.back().id;
  }

  Plan& plan_;
  const PlanOptions& o_;
  double exemplar_pixels_ = 0;
  std::size_t shot_tasks_ = 0;                  // the current shot's first task
  std::unordered_map<std::string, bool> done_;  // task id -> done
  SceneCost scene_;
};

}  // namespace

Plan plan(std::vector<PlannedShot> shots, const PlanOptions& options) {
  if (options.chunk < 1 || options.chunk > kMaxFrameCount)
    throw Error(Error::Field{"chunk"},
                fmt::format("must be in [1, {}], got {}", kMaxFrameCount, options.chunk));
  if (options.threads < 1 || options.threads > 1024)
    throw Error(Error::Field{"threads"},
                fmt::format("must be in [1, 1024], got {}", options.threads));
  Plan p;
  p.chunk = options.chunk;
  p.threads = options.threads;
  std::map<std::string, std::string> names;  // name -> shot file
  std::map<std::string, std::string> folders;
  for (PlannedShot& s : shots) {
    const std::string folder = fs::weakly_canonical(s.shot.outputs.folder).string();
    if (const auto it = folders.find(folder); it != folders.end())
      throw Error(Error::Field{"shots"},
                  fmt::format("'{}' and '{}' write the same output folder '{}'",
                              echo_path(it->second), echo_path(s.path), echo_path(folder)));
    folders[folder] = s.path;
    if (s.name.empty()) s.name = shot_name(s.path);
    if (const auto [it, added] = names.emplace(s.name, s.path); !added)
      throw Error(Error::Field{"shots"},
                  fmt::format("'{}' and '{}' both name their tasks '{}'; rename one",
                              echo_path(it->second), echo_path(s.path), echo(s.name)));
    p.shots.push_back(std::move(s));
  }
  Planner planner(p, options);
  for (int i = 0; i < int(p.shots.size()); ++i) planner.add_shot(i);
  return p;
}

Plan plan(const std::vector<std::string>& shot_paths, const PlanOptions& options) {
  std::vector<PlannedShot> shots;
  for (const std::string& path : shot_paths) shots.push_back({"", path, open(path)});
  return plan(std::move(shots), options);
}

std::string json_string(const std::string& s, const std::string& subject) {
  if (const std::size_t bad = first_invalid_utf8(s); bad != std::string::npos)
    throw Error(subject, fmt::format("'{}...' is not UTF-8 text (byte {} is 0x{:02x}); plan "
                                     "--json cannot carry it: rename it",
                                     echo(std::string_view(s).substr(0, bad)), bad,
                                     unsigned(static_cast<unsigned char>(s[bad]))));
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
          out += fmt::format("\\u{:04x}", int(static_cast<unsigned char>(c)));
        else
          out += c;
    }
  }
  return out + "\"";
}

namespace {

std::string json_strings(const std::vector<std::string>& v, const std::string& subject) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + json_string(v[i], subject);
  return out + "]";
}

}  // namespace

std::string plan_json(const Plan& plan) {
  std::string out = "{\n  \"format\": \"emaki-plan-1\",\n  \"shots\": [\n";
  for (std::size_t i = 0; i < plan.shots.size(); ++i) {
    const PlannedShot& s = plan.shots[i];
    const std::string subject = echo_path(valid_utf8_or_marks(s.path));
    out += fmt::format(
        "    {{\"name\": {}, \"path\": {}, \"output_folder\": {}, \"frames\": [{}, {}], "
        "\"size\": [{}, {}]}}{}\n",
        json_string(s.name, subject), json_string(s.path, subject),
        json_string(s.shot.outputs.folder, subject + ": outputs.folder"), s.shot.source.first_frame,
        s.shot.source.last_frame, s.shot.source.width, s.shot.source.height,
        i + 1 < plan.shots.size() ? "," : "");
  }
  out += "  ],\n  \"tasks\": [\n";
  for (std::size_t i = 0; i < plan.tasks.size(); ++i) {
    const Task& t = plan.tasks[i];
    const std::string subject =
        echo_path(valid_utf8_or_marks(plan.shots[std::size_t(t.shot)].path));
    out += fmt::format(
        "    {{\"id\": {}, \"shot\": {}, \"kind\": \"{}\", \"layer\": {}, \"frames\": [{}, {}], "
        "\"argv\": {}, \"outputs\": {}, \"memory_mb\": {}, \"threads\": {}, \"after\": {}, "
        "\"done\": {}}}{}\n",
        json_string(t.id, subject), json_string(plan.shots[std::size_t(t.shot)].name, subject),
        task_kind_name(t.kind), t.layer.empty() ? "null" : json_string(t.layer, subject),
        t.first_frame, t.last_frame, json_strings(t.argv, subject),
        json_strings(t.outputs, subject), t.memory_mb, t.threads, json_strings(t.after, subject),
        t.done ? "true" : "false", i + 1 < plan.tasks.size() ? "," : "");
  }
  return out + "  ]\n}\n";
}

}  // namespace emaki::shot
