// A production on a render farm: `emaki plan` (the task graph, as a table or JSON), `emaki farm
// submit | status | cancel` (Slurm), and `emaki task KIND SHOT` (one task of the plan: what a
// farm node runs).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "apps/emaki/commands.h"
#include "apps/emaki/huge_pages.h"
#include "apps/emaki/shot_command.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/version.h"
#include "farm/slurm.h"
#include "shot/api.h"
#include "shot/plan.h"

namespace emaki::app {

namespace {

namespace fs = std::filesystem;

// The running binary, so that farm nodes run the same emaki (shared storage).
std::string this_binary() {
  char buf[PATH_MAX] = {};
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, std::size_t(n)) : std::string("emaki");
}

// Shot files and how their plan is cut, shared by plan and every farm subcommand.
struct PlanArgs {
  std::vector<std::string> shots;
  int chunk = 8, threads = 1;

  void bind(CLI::App& app) {
    app.add_option("shots", shots, "shot files (TOML)")->required();
    app.add_option("--chunk", chunk,
                   "frames per passes / layer / composite task (default 8; status: the "
                   "submission's)");
    app.add_option("--threads", threads, "threads (CPUs) per task (default 1)");
  }
  shot::Plan make() const {
    shot::PlanOptions o;
    o.emaki = this_binary();
    o.chunk = chunk;
    o.threads = threads;
    std::vector<std::string> paths;
    for (const std::string& s : shots) paths.push_back(fs::absolute(s).lexically_normal().string());
    return shot::plan(paths, o);
  }
  // The plan cut as the shots were submitted (farm/chunk, farm/threads): task ids name their
  // frames, so status and cancel plan with the submission's settings unless given them again.
  // A different value given on the command line is an error naming it.
  shot::Plan make_as_submitted(const CLI::App& app) {
    shot::Plan plan = make();
    bool changed = false;
    const auto adopt = [&](const char* option, const char* name, int& value,
                           std::optional<int> recorded) {
      if (!recorded || *recorded == value) return;
      if (app.count(option) > 0)
        throw Error(Error::Field{name}, fmt::format("the shots were submitted with {} {}, not {}",
                                                    name, *recorded, value));
      value = *recorded;
      changed = true;
    };
    adopt("--chunk", "chunk", chunk, farm::submitted_chunk(plan));
    adopt("--threads", "threads", threads, farm::submitted_threads(plan));
    return changed ? make() : plan;
  }
};

void print_plan(const shot::Plan& plan) {
  std::printf("%-40s %-9s %7s %6s  %s\n", "task", "kind", "mem MB", "state", "after");
  for (const shot::Task& t : plan.tasks) {
    std::string after;
    for (const std::string& a : t.after) after += (after.empty() ? "" : " ") + a;
    std::printf("%-40s %-9s %7ld %6s  %s\n", t.id.c_str(), shot::task_kind_name(t.kind),
                long(t.memory_mb), t.done ? "done" : "to do", after.c_str());
  }
}

int farm_submit(const Args& args) {
  CLI::App app{"Submits the shots' unfinished tasks to Slurm as job arrays (sbatch).",
               "emaki farm submit"};
  PlanArgs p;
  farm::SlurmOptions o;
  p.bind(app);
  app.add_option("--partition", o.partition, "Slurm partition");
  app.add_option("--account", o.account, "Slurm account");
  app.add_option("--time", o.time, "Slurm time limit per task (e.g. 2:00:00)");
  app.add_flag("--dry-run", o.dry_run, "print the batch scripts; submit and write nothing");
  if (parse_cli(app, args)) return 0;
  const shot::Plan plan = p.make();
  const farm::Submitted s = farm::submit(plan, o);
  if (o.dry_run) {
    for (const std::string& script : s.scripts) std::printf("%s\n", script.c_str());
    return 0;
  }
  for (const std::string& script : s.scripts)
    std::fprintf(stderr, "emaki farm: submitted %s\n", script.c_str());
  std::fprintf(stderr, "emaki farm: %d tasks in %d job arrays submitted, %d finished already\n",
               s.tasks, s.jobs, s.done);
  // For scripts: each job array queued, "JOBID<tab>JOB NAME<tab>TASKS", on stdout.
  for (const farm::SubmittedArray& a : s.arrays)
    std::printf("%s\t%s\t%d\n", a.job.c_str(), a.name.c_str(), a.tasks);
  return 0;
}

int farm_status(const Args& args) {
  CLI::App app{
      "Each task of the shots: pending, running, done, failed (with its log and error "
      "line) or not run. Exit code: 0 all done, 3 some still queued or running, 4 some "
      "failed or not run, 5 some not submitted.",
      "emaki farm status"};
  PlanArgs p;
  bool json = false;
  p.bind(app);
  app.add_flag("--json", json, "one JSON object per task (docs/farm.md)");
  if (parse_cli(app, args)) return 0;
  const shot::Plan plan = p.make_as_submitted(app);
  const std::vector<farm::TaskStatus> states = farm::status(plan);
  if (json) {
    std::printf("%s", farm::status_json(plan, states).c_str());
    return farm::status_exit_code(states);
  }
  std::map<std::string, int> count;
  for (const farm::TaskStatus& st : states) {
    const char* state = farm::task_state_name(st.state);
    ++count[state];
    std::printf("%-40s %-13s %-10s %s\n", st.task->id.c_str(), state, st.job.c_str(),
                st.detail.c_str());
  }
  std::string summary;
  for (const auto& [state, n] : count)
    summary += fmt::format("{}{} {}", summary.empty() ? "" : ", ", n, state);
  std::printf("%s\n", summary.c_str());
  return farm::status_exit_code(states);
}

int farm_cancel(const Args& args) {
  CLI::App app{"Cancels the shots' queued and running jobs (scancel).", "emaki farm cancel"};
  PlanArgs p;
  p.bind(app);
  if (parse_cli(app, args)) return 0;
  const int n = farm::cancel(p.make_as_submitted(app));
  std::fprintf(stderr, "emaki farm: cancelled %d job arrays\n", n);
  return 0;
}

}  // namespace

int run_plan(const Args& args) {
  CLI::App app{
      "The shots as a task graph for a farm scheduler: a table, or JSON (--json; "
      "docs/farm.md documents it).",
      "emaki plan"};
  PlanArgs p;
  bool json = false;
  p.bind(app);
  app.add_flag("--json", json, "print the plan as JSON");
  if (parse_cli(app, args)) return 0;
  const shot::Plan plan = p.make();
  if (json)
    std::printf("%s", shot::plan_json(plan).c_str());
  else
    print_plan(plan);
  return 0;
}

int run_farm(const Args& args) {
  const std::string usage = "usage: emaki farm submit|status|cancel SHOT... (see --help of each)";
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::printf(
        "Runs shots on a Slurm farm.\n%s\n\n"
        "  submit  the shots' unfinished tasks as job arrays (sbatch)\n"
        "  status  each task: pending, running, done, failed (with its log and error line)\n"
        "  cancel  the shots' queued and running jobs (scancel)\n",
        usage.c_str());
    return 0;
  }
  if (args.empty()) throw Error("", usage);
  if (args[0] == "--help" || args[0] == "-h") {
    std::printf(
        "%s\n\n"
        "  submit   queues the shots' unfinished tasks as Slurm job arrays; prints\n"
        "           JOBID<tab>NAME<tab>TASKS for each array queued\n"
        "  status   each task's state; exit 0 all done, 3 queued or running, 4 failed or\n"
        "           not run, 5 not submitted (--json: one object per task)\n"
        "  cancel   cancels the shots' queued and running jobs\n\n"
        "status and cancel plan with the chunk and threads submit recorded under\n"
        "OUTPUT/farm. docs/farm.md has the details.\n",
        usage.c_str());
    return 0;
  }
  const Args rest(args.begin() + 1, args.end());
  if (args[0] == "submit") return farm_submit(rest);
  if (args[0] == "status") return farm_status(rest);
  if (args[0] == "cancel") return farm_cancel(rest);
  throw Error("", usage);
}

int run_task(const Args& args) {
  const std::string usage =
      "usage: emaki task prepare|passes|layer|composite|previews SHOT [--frames A-B] "
      "[--layer NAME] (one task of `emaki plan`)";
  const std::vector<std::string> kinds = {"prepare", "passes", "layer", "composite", "previews"};
  if (!args.empty() && (args[0] == "--help" || args[0] == "-h")) {
    std::printf(
        "One task of a shot's plan, as a farm node runs it.\n%s\n\n"
        "  prepare    the output folders and their settings, before the other tasks\n"
        "  passes     the guide passes of a chunk of frames\n"
        "  layer      a layer's frames: a chunk, or the whole range of a temporal layer\n"
        "  composite  the composited frames of a chunk\n"
        "  previews   the contact sheet and the MP4\n",
        usage.c_str());
    return 0;
  }
  if (args.empty() || std::find(kinds.begin(), kinds.end(), args[0]) == kinds.end())
    throw Error("", usage);
  const std::string kind = args[0];
  CLI::App app{
      "One task of a shot's plan, as a farm node runs it beside the shot's other "
      "tasks.",
      "emaki task " + kind};
  ShotCommand c;
  std::string layer;
  c.bind(app, "FIRST-LAST or FRAME");
  if (kind == "layer") app.add_option("--layer", layer, "the layer")->required();
  if (parse_cli(app, Args(args.begin() + 1, args.end()))) return 0;
  keep_freed_memory();  // a chunk's frames reuse the memory the frames before them freed
  // A task's log (its stdout and stderr) starts with the emaki that ran it: which version made
  // a frame on the farm. On stdout, so that an error stays stderr's one line.
  std::printf("emaki task: emaki %s\n", version());
  std::fflush(stdout);
  const pipeline::Shot shot = shot::open(c.shot_path);
  shot::Request r = c.request("task");
  r.farm_task = true;
  r.previews = false;
  if (kind == "prepare") {
    shot::prepare(shot, r);
  } else if (kind == "passes") {
    const int n = shot::render_passes(shot, r);
    std::fprintf(stderr, "emaki task: %d frames of passes rendered\n", n);
  } else if (kind == "layer") {
    if (!shot.find_layer(layer))
      throw Error(Error::Field{"layer"}, fmt::format("no layer '{}' in the shot", echo(layer)));
    r.layers = {layer};
    r.composite = false;
    const shot::RunResult res = shot::run(shot, r);
    end_progress_line();
    std::fprintf(stderr, "emaki task: layer %s: %d frames synthesized, %d finished already\n",
                 layer.c_str(), res.report.synthesized, res.report.reused);
  } else if (kind == "composite") {
    r.progress = nullptr;
    std::fprintf(stderr, "emaki task: %d frames composited\n", shot::composite(shot, r).composited);
  } else if (kind == "previews") {
    for (const std::string& f : shot::write_previews(shot, r))
      std::fprintf(stderr, "emaki task: wrote %s\n", f.c_str());
  } else {
    throw Error("", usage);
  }
  return 0;
}

}  // namespace emaki::app
