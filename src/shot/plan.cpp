#include "shot/plan.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <map>

#include "core/error.h"
#include "core/limits.h"
#include "io/image_io.h"
#include "shot/api.h"
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

// Peak resident memory of a task in MB, from the frame size and the exemplars' sizes. The
// constants are peak RSS per pixel measured with /usr/bin/time on `emaki task` at 160x90,
// 480x270 and 960x540 with the StyLit exemplar (docs/farm.md), plus a quarter for margin.
int64_t memory_estimate(const pipeline::Shot& s, double exemplar_pixels, TaskKind kind) {
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
  const int64_t with_margin = int64_t(mb * 1.25) + 1;
  return (with_margin + 63) / 64 * 64;
}

// The exemplars' painting pixels (they dominate a small shot's memory).
double exemplar_pixels(const pipeline::Shot& s) {
  double px = 0;
  for (const pipeline::Exemplar& e : s.exemplars) {
    const io::AnyImage img = io::read_image(e.painting);
    px += double(img.width()) * img.height();
  }
  return px;
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
    const io::FileStore state(s, io::StoreMode::kRun, io::StoreAccess::kInspect);
    const std::string& out = s.outputs.folder;
    const int first = s.source.first_frame, last = s.source.last_frame;
    exemplar_pixels_ = exemplar_pixels(s);

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
    std::vector<std::string> passes;
    if (scene)
      for (int a = first; a <= last; a += o_.chunk) {
        const int b = std::min(last, a + o_.chunk - 1);
        passes.push_back(add(index, TaskKind::kPasses, "", a, b, {out + "/passes"}, {prepare},
                             passes_done(a, b)));
      }
    const std::vector<std::string> before_layers = scene ? passes : std::vector{prepare};
    std::vector<std::string> layers;
    for (const pipeline::Layer& l : s.layers) {
      const int step = l.temporal.enabled ? last - first + 1 : o_.chunk;
      for (int a = first; a <= last; a += step) {
        const int b = std::min(last, a + step - 1);
        bool done = true;
        for (int f = a; f <= b && done; ++f) done = state.has_layer(l, f);
        layers.push_back(add(index, TaskKind::kLayer, l.name, a, b, {out + "/layers/" + l.name},
                             before_layers, done));
      }
    }
    std::vector<std::string> composites;
    for (int a = first; a <= last; a += o_.chunk) {
      const int b = std::min(last, a + o_.chunk - 1);
      bool done = true;
      for (int f = a; f <= b && done; ++f) done = state.has_frame(f);
      composites.push_back(add(index, TaskKind::kComposite, "", a, b,
                               {out + "/composite", out + "/layered"}, layers, done));
    }
    // Previews are cheap and are remade whenever anything else is.
    bool all_done = true;
    for (const Task& t : plan_.tasks) all_done = all_done && (t.shot != index || t.done);
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
    t.argv = {o_.emaki, "task", task_kind_name(kind), ps.path};
    if (!layer.empty()) t.argv.insert(t.argv.end(), {"--layer", layer});
    if (kind != TaskKind::kPrepare && kind != TaskKind::kPreviews)
      t.argv.insert(t.argv.end(), {"--frames", frames_text(a, b)});
    t.threads = o_.threads;
    t.argv.insert(t.argv.end(), {"--threads", std::to_string(o_.threads)});
    t.outputs = std::move(outputs);
    t.memory_mb = memory_estimate(ps.shot, exemplar_pixels_, kind);
    t.done = done;
    for (const std::string& id : after)
      if (!find(id)->done) t.after.push_back(id);
    plan_.tasks.push_back(std::move(t));
    return plan_.tasks.back().id;
  }

  const Task* find(const std::string& id) const {
    for (const Task& t : plan_.tasks)
      if (t.id == id) return &t;
    return nullptr;
  }

  Plan& plan_;
  const PlanOptions& o_;
  double exemplar_pixels_ = 0;
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
  std::map<std::string, int> names;
  std::map<std::string, std::string> folders;
  for (PlannedShot& s : shots) {
    const std::string folder = fs::weakly_canonical(s.shot.outputs.folder).string();
    if (const auto it = folders.find(folder); it != folders.end())
      throw Error(Error::Field{"shots"},
                  fmt::format("'{}' and '{}' write the same output folder '{}'",
                              echo_path(it->second), echo_path(s.path), echo_path(folder)));
    folders[folder] = s.path;
    if (s.name.empty()) s.name = fs::path(s.path).stem().string();
    if (const int n = names[s.name]++; n > 0) s.name += fmt::format("-{}", n + 1);
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

namespace {

std::string json_string(const std::string& s) {
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

std::string json_strings(const std::vector<std::string>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + json_string(v[i]);
  return out + "]";
}

}  // namespace

std::string plan_json(const Plan& plan) {
  std::string out = "{\n  \"format\": \"emaki-plan-1\",\n  \"shots\": [\n";
  for (std::size_t i = 0; i < plan.shots.size(); ++i) {
    const PlannedShot& s = plan.shots[i];
    out += fmt::format(
        "    {{\"name\": {}, \"path\": {}, \"output_folder\": {}, \"frames\": [{}, {}], "
        "\"size\": [{}, {}]}}{}\n",
        json_string(s.name), json_string(s.path), json_string(s.shot.outputs.folder),
        s.shot.source.first_frame, s.shot.source.last_frame, s.shot.source.width,
        s.shot.source.height, i + 1 < plan.shots.size() ? "," : "");
  }
  out += "  ],\n  \"tasks\": [\n";
  for (std::size_t i = 0; i < plan.tasks.size(); ++i) {
    const Task& t = plan.tasks[i];
    out += fmt::format(
        "    {{\"id\": {}, \"shot\": {}, \"kind\": \"{}\", \"layer\": {}, \"frames\": [{}, {}], "
        "\"argv\": {}, \"outputs\": {}, \"memory_mb\": {}, \"threads\": {}, \"after\": {}, "
        "\"done\": {}}}{}\n",
        json_string(t.id), json_string(plan.shots[std::size_t(t.shot)].name),
        task_kind_name(t.kind), t.layer.empty() ? "null" : json_string(t.layer), t.first_frame,
        t.last_frame, json_strings(t.argv), json_strings(t.outputs), t.memory_mb, t.threads,
        json_strings(t.after), t.done ? "true" : "false", i + 1 < plan.tasks.size() ? "," : "");
  }
  return out + "  ]\n}\n";
}

}  // namespace emaki::shot
