#include "farm/slurm.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/limits.h"
#include "farm/process.h"
#include "store/file_store.h"
#include "store/output_store.h"

namespace emaki::farm {

namespace fs = std::filesystem;
using shot::Plan;
using shot::Task;

const char* task_state_name(TaskState s) {
  switch (s) {
    case TaskState::kDone:
      return "done";
    case TaskState::kRunning:
      return "running";
    case TaskState::kPending:
      return "pending";
    case TaskState::kFailed:
      return "failed";
    case TaskState::kNotRun:
      return "not run";
    case TaskState::kNotSubmitted:
      return "not submitted";
  }
  return "?";
}

namespace {

std::string farm_folder(const Plan& plan, int shot) {
  return plan.shots[std::size_t(shot)].shot.outputs.folder + "/farm";
}

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// What a failed command said: its first line of stderr.
std::string first_line(const std::string& text) {
  return echo(text.substr(0, text.find('\n')), 300);
}

// farm/jobs.tsv: "TASK \t JOBID \t INDEX" per submitted task; a later line wins.
std::map<std::string, std::string> read_jobs(const std::string& folder) {
  std::map<std::string, std::string> jobs;
  std::ifstream in(folder + "/jobs.tsv");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string task, job, index;
    if (std::getline(ss, task, '\t') && std::getline(ss, job, '\t') && std::getline(ss, index))
      jobs[task] = job + "_" + index;
  }
  return jobs;
}

void append_jobs(const std::string& folder, const std::vector<const Task*>& tasks,
                 const std::string& job) {
  std::ofstream out(folder + "/jobs.tsv", std::ios::app);
  for (std::size_t i = 0; i < tasks.size(); ++i)
    out << tasks[i]->id << '\t' << job << '\t' << i << '\n';
  if (!out) throw Error(folder + "/jobs.tsv", "cannot record the submitted jobs");
}

// farm/chunk: the chunk of the last submission, one decimal number.
void record_chunk(const std::string& folder, int chunk) {
  fs::create_directories(folder);
  const std::string path = folder + "/chunk";
  io::TempFile tmp(path, path);
  const std::string text = fmt::format("{}\n", chunk);
  tmp.write(text.data(), text.size());
  tmp.commit();
}

std::optional<int> read_chunk(const std::string& folder) {
  const std::string path = folder + "/chunk";
  std::ifstream in(path);
  if (!in) return std::nullopt;
  char buf[32] = {};
  in.read(buf, sizeof buf - 1);
  std::string text(buf, std::size_t(in.gcount()));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  int chunk = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), chunk);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || chunk < 1 ||
      chunk > kMaxFrameCount)
    throw Error(path, fmt::format("is not a chunk of frames in [1, {}]: '{}'; submit the shot "
                                  "again or pass --chunk",
                                  kMaxFrameCount, echo(text, 40)));
  return chunk;
}

// The queue: "JOBID_INDEX" -> (state, reason), every array element on its own line.
std::map<std::string, std::pair<std::string, std::string>> queue() {
  const ProcessResult r = run_process({"squeue", "-h", "-r", "-o", "%i|%T|%r"});
  if (r.exit_code != 0)
    throw Error("squeue", fmt::format("failed ({}): {}", r.exit_code, first_line(r.err)));
  std::map<std::string, std::pair<std::string, std::string>> q;
  std::istringstream ss(r.out);
  std::string line;
  while (std::getline(ss, line)) {
    const std::size_t a = line.find('|'), b = line.find('|', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    std::string id = line.substr(0, a);
    if (id.find('_') == std::string::npos) id += "_0";
    q[id] = {line.substr(a + 1, b - a - 1), line.substr(b + 1)};
  }
  return q;
}

std::string job_of(const std::string& element) {
  return element.substr(0, element.find('_'));
}

}  // namespace

std::string batch_script(const Plan& plan, const std::vector<const Task*>& tasks,
                         const std::vector<std::string>& depends, const SlurmOptions& o) {
  const Task& first = *tasks.front();
  const std::string farm = farm_folder(plan, first.shot);
  int64_t memory = 0;
  int threads = 1;
  for (const Task* t : tasks) memory = std::max(memory, t->memory_mb), threads = t->threads;
  std::string s = "#!/bin/sh\n";
  s += fmt::format("#SBATCH --job-name=emaki:{}:{}\n", plan.shots[std::size_t(first.shot)].name,
                   shot::task_kind_name(first.kind));
  s += fmt::format("#SBATCH --array=0-{}\n", tasks.size() - 1);
  s += fmt::format("#SBATCH --output={}/logs/slurm-%A_%a.log\n", farm);
  s += fmt::format("#SBATCH --cpus-per-task={}\n#SBATCH --mem={}M\n", threads, memory);
  if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.account.empty()) s += "#SBATCH --account=" + o.account + "\n";
  if (!o.time.empty()) s += "#SBATCH --time=" + o.time + "\n";
  if (!depends.empty()) {
    std::string ids;
    for (const std::string& d : depends) ids += ":" + d;
    s += "#SBATCH --dependency=afterok" + ids + "\n#SBATCH --kill-on-invalid-dep=yes\n";
  }
  s += "# Written by `emaki farm submit`: one case per task of the array.\n";
  s += "case \"$SLURM_ARRAY_TASK_ID\" in\n";
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    std::string argv;
    for (const std::string& a : tasks[i]->argv) argv += fmt::format(" {}", quoted(a));
    s += fmt::format("  {}) TASK={}; set --{} ;;\n", i, quoted(tasks[i]->id), argv);
  }
  s += "  *) echo \"emaki farm: no task $SLURM_ARRAY_TASK_ID in this array\" >&2; exit 2 ;;\n";
  s += "esac\n";
  s += "FARM=" + quoted(farm) + "\n";
  s += "rm -f \"$FARM/status/$TASK.exit\"\n";
  s += "date +%s.%N >\"$FARM/status/$TASK.start\"\n";
  s += "\"$@\" >\"$FARM/logs/$TASK.log\" 2>&1\n";
  s += "rc=$?\n";
  s += "date +%s.%N >\"$FARM/status/$TASK.end\"\n";
  s += "echo \"$rc\" >\"$FARM/status/$TASK.exit.tmp\" && mv \"$FARM/status/$TASK.exit.tmp\" "
       "\"$FARM/status/$TASK.exit\"\n";
  s += "exit \"$rc\"\n";
  return s;
}

namespace {

// The queued jobs of a shot from earlier submissions: submitting over them would run a task
// twice at once.
void check_nothing_queued(const Plan& plan, int shot,
                          const std::map<std::string, std::pair<std::string, std::string>>& q) {
  std::set<std::string> queued;
  for (const auto& [task, element] : read_jobs(farm_folder(plan, shot)))
    if (q.count(element)) queued.insert(job_of(element));
  if (queued.empty()) return;
  std::string ids;
  for (const std::string& j : queued) ids += (ids.empty() ? "" : ", ") + j;
  throw Error(
      plan.shots[std::size_t(shot)].path,
      fmt::format("has jobs in the queue ({}); wait for them or run `emaki farm cancel`", ids));
}

std::string sbatch(const std::string& script_path) {
  const ProcessResult r = run_process({"sbatch", "--parsable", script_path});
  if (r.exit_code != 0)
    throw Error("sbatch",
                fmt::format("refused '{}' ({}): {}", script_path, r.exit_code, first_line(r.err)));
  std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw Error("sbatch", fmt::format("printed no job id for '{}': {}", script_path, echo(r.out)));
  return id;
}

}  // namespace

Submitted submit(const Plan& plan, const SlurmOptions& o) {
  Submitted out;
  const auto q = o.dry_run ? decltype(queue())() : queue();
  for (int s = 0; s < int(plan.shots.size()); ++s) {
    const std::string farm = farm_folder(plan, s);
    if (!o.dry_run) {
      check_nothing_queued(plan, s, q);
      // No task of the shot runs now: what a cancelled or killed task left half-written goes
      // (farm tasks leave clean-up to each other), as `emaki run` does when it starts.
      io::FileStore(plan.shots[std::size_t(s)].shot, io::StoreMode::kRun, io::StoreAccess::kAlone);
      record_chunk(farm, plan.chunk);
    }
    std::map<std::string, std::string> job_of_task;  // this submission's
    for (shot::TaskKind kind :
         {shot::TaskKind::kPrepare, shot::TaskKind::kPasses, shot::TaskKind::kLayer,
          shot::TaskKind::kComposite, shot::TaskKind::kPreviews}) {
      std::vector<const Task*> tasks;
      std::set<std::string> depends;
      for (const Task& t : plan.tasks) {
        if (t.shot != s || t.kind != kind) continue;
        if (t.done) {
          ++out.done;
          continue;
        }
        tasks.push_back(&t);
        for (const std::string& a : t.after)
          depends.insert(o.dry_run ? "{" + a + "}" : job_of_task.at(a));
      }
      if (tasks.empty()) continue;
      const std::string script = batch_script(plan, tasks, {depends.begin(), depends.end()}, o);
      ++out.jobs;
      out.tasks += int(tasks.size());
      if (o.dry_run) {
        out.scripts.push_back(script);
        continue;
      }
      for (const char* sub : {"", "/logs", "/status", "/scripts"})
        fs::create_directories(farm + sub);
      const std::string path = fmt::format("{}/scripts/{}.sh", farm, shot::task_kind_name(kind));
      io::TempFile tmp(path, path);
      tmp.write(script.data(), script.size());
      tmp.commit();
      // A task's record starts afresh: no exit code or log of an earlier submission.
      for (const Task* t : tasks)
        for (const char* f : {"/status/{}.exit", "/status/{}.exit.tmp", "/logs/{}.log"})
          fs::remove(farm + fmt::format(fmt::runtime(f), t->id));
      const std::string job = sbatch(path);
      append_jobs(farm, tasks, job);
      for (const Task* t : tasks) job_of_task[t->id] = job;
      out.scripts.push_back(path);
    }
  }
  return out;
}

namespace {

// The line of a failed task's log that says why: its last error line, else its last line.
std::string error_line(const std::string& log) {
  std::ifstream in(log);
  std::string line, last, error;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    last = line;
    if (line.find("error") != std::string::npos) error = line;
  }
  return echo(error.empty() ? last : error, 300);
}

TaskStatus status_of(const Plan& plan, const Task& t,
                     const std::map<std::string, std::string>& jobs,
                     const std::map<std::string, std::pair<std::string, std::string>>& q) {
  TaskStatus st;
  st.task = &t;
  const std::string farm = farm_folder(plan, t.shot);
  const auto job = jobs.find(t.id);
  if (job != jobs.end()) st.job = job->second;
  if (const auto it = q.find(st.job); !st.job.empty() && it != q.end()) {
    const std::string& state = it->second.first;
    const bool pending = state == "PENDING";
    st.state = pending ? TaskState::kPending : TaskState::kRunning;
    st.detail = pending ? it->second.second : state;
    return st;
  }
  std::ifstream exit_file(farm + "/status/" + t.id + ".exit");
  int code = -1;
  if (exit_file >> code) {
    const std::string log = farm + "/logs/" + t.id + ".log";
    st.state = code == 0 ? TaskState::kDone : TaskState::kFailed;
    if (code != 0) st.detail = fmt::format("exit {}; {}: {}", code, log, error_line(log));
    return st;
  }
  if (t.done) {
    st.state = TaskState::kDone;
    return st;
  }
  const std::string log = farm + "/logs/" + t.id + ".log";
  std::error_code ec;
  if (!st.job.empty() && fs::is_regular_file(log, ec)) {
    st.state = TaskState::kFailed;
    st.detail = fmt::format("stopped while running (cancelled or killed); {}", log);
    return st;
  }
  st.state = st.job.empty() ? TaskState::kNotSubmitted : TaskState::kNotRun;
  if (!st.job.empty())
    st.detail = "left the queue without running (cancelled, or a task it waits for failed)";
  return st;
}

}  // namespace

std::vector<TaskStatus> status(const Plan& plan) {
  const auto q = queue();
  std::vector<std::map<std::string, std::string>> jobs;
  for (int s = 0; s < int(plan.shots.size()); ++s) jobs.push_back(read_jobs(farm_folder(plan, s)));
  std::vector<TaskStatus> out;
  for (const Task& t : plan.tasks) out.push_back(status_of(plan, t, jobs[std::size_t(t.shot)], q));
  return out;
}

std::optional<int> submitted_chunk(const Plan& plan) {
  std::optional<int> chunk;
  std::string first;
  for (int s = 0; s < int(plan.shots.size()); ++s) {
    const std::optional<int> c = read_chunk(farm_folder(plan, s));
    if (!c) continue;
    const std::string& path = plan.shots[std::size_t(s)].path;
    if (chunk && *c != *chunk)
      throw Error(Error::Field{"chunk"},
                  fmt::format("'{}' was submitted with chunk {} and '{}' with {}: ask for them "
                              "one at a time",
                              echo_path(first), *chunk, echo_path(path), *c));
    chunk = c;
    first = path;
  }
  return chunk;
}

int cancel(const Plan& plan) {
  const auto q = queue();
  std::set<std::string> ids;
  for (int s = 0; s < int(plan.shots.size()); ++s)
    for (const auto& [task, element] : read_jobs(farm_folder(plan, s)))
      if (q.count(element)) ids.insert(job_of(element));
  if (ids.empty()) return 0;
  std::vector<std::string> argv = {"scancel"};
  argv.insert(argv.end(), ids.begin(), ids.end());
  const ProcessResult r = run_process(argv);
  if (r.exit_code != 0)
    throw Error("scancel", fmt::format("failed ({}): {}", r.exit_code, first_line(r.err)));
  return int(ids.size());
}

}  // namespace emaki::farm
