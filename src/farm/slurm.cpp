#include "farm/slurm.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

#include "core/error.h"
#include "core/limits.h"
#include "core/shot_keys.h"
#include "core/utf8.h"
#include "farm/farm_state.h"
#include "farm/process.h"
#include "farm/script_text.h"
#include "store/file_store.h"
#include "store/output_store.h"

namespace emaki::farm {

namespace fs = std::filesystem;
using shot::Plan;
using shot::PlannedShot;
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

// What a failed command said: its first line of stderr.
std::string first_line(const std::string& text) {
  return echo(text.substr(0, text.find('\n')), 300);
}

// farm/jobs.tsv: "TASK \t JOBID \t INDEX" per submitted task; a later line wins.
std::map<std::string, std::string> read_jobs(const std::string& folder) {
  const std::string path = folder + "/jobs.tsv";
  const std::optional<std::string> text = read_state_file(path, kMaxJobsFileBytes);
  return text ? parse_jobs(*text, path) : std::map<std::string, std::string>{};
}

// Appends the records with one write, then fsync and close, each checked: a record that did not
// reach the disk is an error before another job is queued.
void append_jobs(const std::string& folder, const std::vector<const Task*>& tasks,
                 const std::string& job) {
  const std::string path = folder + "/jobs.tsv";
  std::string text;
  for (std::size_t i = 0; i < tasks.size(); ++i) text += job_record(tasks[i]->id, job, i);
  const auto failed = [&](const char* what) {
    return Error(path,
                 fmt::format("cannot record job {} ({}: {})", job, what, std::strerror(errno)));
  };
  const int fd = ::open(path.c_str(),
                        O_WRONLY | O_APPEND | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  if (fd < 0) throw failed("open");
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    errno = EINVAL;
    throw failed("not a regular file");
  }
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      ::close(fd);
      throw failed("write");
    }
    done += std::size_t(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    throw failed("fsync");
  }
  if (::close(fd) != 0) throw failed("close");
}

// farm/chunk and farm/threads: the plan's cut at the last submission, one decimal number each.
void record_setting(const std::string& folder, const char* name, int value) {
  fs::create_directories(folder);
  const std::string path = folder + "/" + name;
  io::TempFile tmp(path, path);
  const std::string text = fmt::format("{}\n", value);
  tmp.write(text.data(), text.size());
  tmp.commit();
}

std::optional<int> read_setting(const std::string& folder, const char* name) {
  const std::string path = folder + "/" + name;
  const std::optional<std::string> text = read_state_file(path, kMaxSmallFileBytes);
  if (!text) return std::nullopt;
  return std::string_view(name) == "chunk" ? parse_chunk(*text, path) : parse_threads(*text, path);
}

// The submitting user: squeue and scancel see no one else's jobs.
std::string user_id() {
  return std::to_string(::getuid());
}

// The queue: "JOBID_INDEX" -> (state, reason, job name), every array element on its own line.
std::map<std::string, QueuedJob> queue() {
  const ProcessResult r = run_process({"squeue", "-h", "-r", "-u", user_id(), "-o", "%i|%T|%r|%j"});
  if (r.exit_code != 0) throw Error("squeue", slurm_failure("squeue", r.exit_code, r.err));
  return parse_queue(r.out);
}

std::string job_of(const std::string& element) {
  return element.substr(0, element.find('_'));
}

// The job name of a shot's array of one task kind: a job in the queue is the shot's own only
// when it carries one of these names (a copied or stale jobs.tsv names other jobs).
std::string job_name(const Plan& plan, int shot, shot::TaskKind kind) {
  return fmt::format("emaki:{}:{}", job_name_part(plan.shots[std::size_t(shot)].name),
                     shot::task_kind_name(kind));
}

bool shot_owns(const Plan& plan, int shot, const std::string& name) {
  for (shot::TaskKind kind :
       {shot::TaskKind::kPrepare, shot::TaskKind::kPasses, shot::TaskKind::kLayer,
        shot::TaskKind::kComposite, shot::TaskKind::kPreviews})
    if (name == job_name(plan, shot, kind)) return true;
  return false;
}

// The shot's recorded jobs that are in the queue under one of its own names: job id -> name.
std::map<std::string, std::string> queued_jobs(const Plan& plan, int shot,
                                               const std::map<std::string, QueuedJob>& q) {
  std::map<std::string, std::string> out;
  for (const auto& [task, element] : read_jobs(farm_folder(plan, shot)))
    if (const auto it = q.find(element); it != q.end() && shot_owns(plan, shot, it->second.name))
      out[job_of(element)] = it->second.name;
  return out;
}

// sbatch's arguments for a shot's scripts: the farm folder as the working directory and the Slurm
// log under it. As arguments, not #SBATCH lines, the folder's path may hold spaces; Slurm
// expands % anywhere in --output (the working directory included), so its % are doubled.
std::vector<std::string> sbatch_options(const std::string& farm, const std::string& subject) {
  return {"--chdir=" + farm,
          "--output=" + slurm_pattern_literal(farm, subject) + "/logs/slurm-%A_%a.log"};
}

// The #SBATCH lines of an array of tasks. Only values that pass directive_value reach them; the
// farm folder does not (sbatch's own arguments carry --chdir and --output).
std::string directives(const Plan& plan, const std::vector<const Task*>& tasks,
                       const std::vector<std::string>& depends, const SlurmOptions& o) {
  const Task& first = *tasks.front();
  int64_t memory = 0;
  int threads = 1;
  for (const Task* t : tasks) memory = std::max(memory, t->memory_mb), threads = t->threads;
  std::string s =
      fmt::format("#SBATCH --job-name={}\n",
                  directive_value(job_name(plan, first.shot, first.kind), "job name", "._-:"));
  s += fmt::format("#SBATCH --array=0-{}\n", tasks.size() - 1);
  s += fmt::format("#SBATCH --cpus-per-task={}\n#SBATCH --mem={}M\n", threads, memory);
  using Option = std::tuple<const char*, const std::string*, const char*>;
  for (const auto& [name, value, allowed] :
       {Option{"partition", &o.partition, "._-,"}, Option{"account", &o.account, "._-"},
        Option{"time", &o.time, ":-"}})
    if (!value->empty())
      s += fmt::format("#SBATCH --{}={}\n", name,
                       directive_value(*value, fmt::format("--{}", name), allowed));
  if (!depends.empty()) {
    std::string ids;
    for (const std::string& d : depends) ids += ":" + directive_value(d, "dependency", "{}._-:");
    s += "#SBATCH --dependency=afterok" + ids + "\n#SBATCH --kill-on-invalid-dep=yes\n";
  }
  return s;
}

}  // namespace

std::string batch_script(const Plan& plan, const std::vector<const Task*>& tasks,
                         const std::vector<std::string>& depends, const SlurmOptions& o) {
  const Task& first = *tasks.front();
  const PlannedShot& shot = plan.shots[std::size_t(first.shot)];
  const std::string farm = farm_folder(plan, first.shot);
  // Errors name the shot file; one whose path is not UTF-8 is named with '?' for its bad bytes.
  const std::string subject = echo_path(valid_utf8_or_marks(shot.path));
  const std::string folder_subject = fmt::format("{}: {}", subject, shot_keys::kOutputsFolder);
  const std::string farm_word = shell_word(farm, folder_subject);
  std::string s = "#!/bin/sh\n" + directives(plan, tasks, depends, o);
  s += "# Written by `emaki farm submit`, which submits it as\n# sbatch --parsable";
  for (const std::string& a : sbatch_options(farm, folder_subject))
    s += " " + shell_word(a, folder_subject);
  s += " SCRIPT\n# One case per task of the array.\n";
  s += "case \"$SLURM_ARRAY_TASK_ID\" in\n";
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    std::string argv;
    for (const std::string& a : tasks[i]->argv)
      argv += " " + shell_word(a, fmt::format("{}: task {}", subject,
                                              echo(valid_utf8_or_marks(tasks[i]->id))));
    s += fmt::format("  {}) TASK={}; set --{} ;;\n", i, shell_word(tasks[i]->id, subject), argv);
  }
  s += "  *) echo \"emaki farm: no task $SLURM_ARRAY_TASK_ID in this array\" >&2; exit 2 ;;\n";
  s += "esac\n";
  s += "FARM=" + farm_word + "\n";
  // Each record is made afresh: rm takes away whatever is at its path (a symlink planted there
  // included) and noclobber creates the file exclusively, so nothing is written through a link.
  s += "put() { rm -f \"$2\" && (set -C; printf '%s\\n' \"$1\" >\"$2\"); }\n";
  s += "rm -f \"$FARM/status/$TASK.exit\"\n";
  s += "put \"$(date +%s.%N)\" \"$FARM/status/$TASK.start\"\n";
  s += "rm -f \"$FARM/logs/$TASK.log\"\n";
  // emaki starts itself again to take glibc's huge-page tunable (apps/emaki/huge_pages.h), a
  // second load of every library (20 ms of CPU); named here, each task starts once. A setting of
  // the submitting environment (=0 turns huge pages off) is left as it is.
  s += "case \":${GLIBC_TUNABLES-}:\" in *:glibc.malloc.hugetlb=*) ;; *) GLIBC_TUNABLES="
       "\"${GLIBC_TUNABLES:+$GLIBC_TUNABLES:}glibc.malloc.hugetlb=1\"; export GLIBC_TUNABLES ;; "
       "esac\n";
  s += "(set -C; exec \"$@\" >\"$FARM/logs/$TASK.log\" 2>&1)\n";
  s += "rc=$?\n";
  s += "put \"$(date +%s.%N)\" \"$FARM/status/$TASK.end\"\n";
  // mv -T renames over the path itself: a symlink there is replaced, not followed.
  s += "put \"$rc\" \"$FARM/status/$TASK.exit.tmp\" && mv -f -T \"$FARM/status/$TASK.exit.tmp\" "
       "\"$FARM/status/$TASK.exit\"\n";
  s += "exit \"$rc\"\n";
  return s;
}

namespace {

// The queued jobs of a shot from earlier submissions: submitting over them would run a task
// twice at once.
void check_nothing_queued(const Plan& plan, int shot, const std::map<std::string, QueuedJob>& q) {
  const std::map<std::string, std::string> queued = queued_jobs(plan, shot, q);
  if (queued.empty()) return;
  std::string ids;
  for (const auto& [job, name] : queued) ids += (ids.empty() ? "" : ", ") + job;
  throw Error(
      plan.shots[std::size_t(shot)].path,
      fmt::format("has jobs in the queue ({}); wait for them or run `emaki farm cancel`", ids));
}

std::string sbatch(const std::string& script_path, const std::vector<std::string>& options) {
  std::vector<std::string> argv = {"sbatch", "--parsable"};
  argv.insert(argv.end(), options.begin(), options.end());
  argv.push_back(script_path);
  const ProcessResult r = run_process(argv);
  if (r.exit_code != 0)
    throw Error("sbatch", fmt::format("refused '{}': {}", echo_path(script_path),
                                      slurm_failure("sbatch", r.exit_code, r.err)));
  std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
  if (id.empty() || id.size() > 18 || id.find_first_not_of("0123456789") != std::string::npos)
    throw Error("sbatch",
                fmt::format("printed no job id for '{}': {}", echo_path(script_path), echo(r.out)));
  return id;
}

// Cancels jobs of the submitting user, each only under the job name it was recorded with.
void scancel(const std::map<std::string, std::string>& job_names) {
  std::map<std::string, std::vector<std::string>> by_name;
  for (const auto& [job, name] : job_names) by_name[name].push_back(job);
  for (const auto& [name, ids] : by_name) {
    std::vector<std::string> argv = {"scancel", "--user=" + user_id(), "--name=" + name};
    argv.insert(argv.end(), ids.begin(), ids.end());
    const ProcessResult r = run_process(argv);
    if (r.exit_code != 0) throw Error("scancel", slurm_failure("scancel", r.exit_code, r.err));
  }
}

// Submits one array; its records are on disk before the next array is queued, or it is
// cancelled and the error names jobs.tsv.
std::string submit_array(const std::string& farm, const std::string& path,
                         const std::vector<const Task*>& tasks, const std::string& name) {
  const std::string job = sbatch(path, sbatch_options(farm, shot_keys::kOutputsFolder));
  try {
    append_jobs(farm, tasks, job);
  } catch (const Error& e) {
    std::string cancelled = "it was cancelled";
    try {
      scancel({{job, name}});
    } catch (const Error&) {
      cancelled = "cancel it with scancel " + job;
    }
    throw Error(e.subject(), e.message() + "; " + cancelled);
  }
  return job;
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
      record_setting(farm, "chunk", plan.chunk);
      record_setting(farm, "threads", plan.threads);
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
        for (const std::string& a : t.after) depends.insert(job_of_task.at(a));
      }
      if (tasks.empty()) continue;
      const std::string script = batch_script(plan, tasks, {depends.begin(), depends.end()}, o);
      ++out.jobs;
      out.tasks += int(tasks.size());
      if (o.dry_run) {
        for (const Task* t : tasks) job_of_task[t->id] = "{" + job_name(plan, s, kind) + "}";
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
      const std::string job = submit_array(farm, path, tasks, job_name(plan, s, kind));
      for (const Task* t : tasks) job_of_task[t->id] = job;
      out.arrays.push_back({job, job_name(plan, s, kind), int(tasks.size())});
      out.scripts.push_back(path);
    }
  }
  return out;
}

namespace {

// The line of a failed task's log that says why: its last error line, else its last line. Only
// the log's tail is read: a log of gigabytes (or /dev/zero in its place) costs no more.
std::string error_line(const std::string& log) {
  const std::string text = read_file_tail(log, kLogTailBytes).value_or("");
  std::string last, error;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.empty()) continue;
    last = line;
    if (line.find("error") != std::string::npos) error = line;
  }
  return echo(error.empty() ? last : error, 300);
}

TaskStatus status_of(const Plan& plan, const Task& t,
                     const std::map<std::string, std::string>& jobs,
                     const std::map<std::string, QueuedJob>& q) {
  TaskStatus st;
  st.task = &t;
  const std::string farm = farm_folder(plan, t.shot);
  const auto job = jobs.find(t.id);
  if (job != jobs.end()) st.job = job->second;
  if (const auto it = q.find(st.job);
      !st.job.empty() && it != q.end() && it->second.name == job_name(plan, t.shot, t.kind)) {
    const bool pending = it->second.state == "PENDING";
    st.state = pending ? TaskState::kPending : TaskState::kRunning;
    st.detail = pending ? it->second.reason : it->second.state;
    return st;
  }
  const std::optional<std::string> exit_text =
      read_state_file(farm + "/status/" + t.id + ".exit", kMaxSmallFileBytes);
  if (const std::optional<int> code = exit_text ? parse_exit_code(*exit_text) : std::nullopt) {
    const std::string log = farm + "/logs/" + t.id + ".log";
    st.state = *code == 0 ? TaskState::kDone : TaskState::kFailed;
    st.exit_code = code;
    st.log = log;
    if (*code != 0) {
      st.error_line = error_line(log);
      st.detail = fmt::format("exit {}; {}: {}", *code, log, st.error_line);
    }
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
    st.log = log;
    st.error_line = "stopped while running (cancelled or killed)";
    st.detail = fmt::format("{}; {}", st.error_line, log);
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

namespace {

std::optional<int> submitted_setting(const Plan& plan, const char* name) {
  std::optional<int> value;
  std::string first;
  for (int s = 0; s < int(plan.shots.size()); ++s) {
    const std::optional<int> c = read_setting(farm_folder(plan, s), name);
    if (!c) continue;
    const std::string& path = plan.shots[std::size_t(s)].path;
    if (value && *c != *value)
      throw Error(Error::Field{name},
                  fmt::format("'{}' was submitted with {} {} and '{}' with {}: ask for them "
                              "one at a time",
                              echo_path(first), name, *value, echo_path(path), *c));
    value = c;
    first = path;
  }
  return value;
}

}  // namespace

std::optional<int> submitted_chunk(const Plan& plan) {
  return submitted_setting(plan, "chunk");
}

std::optional<int> submitted_threads(const Plan& plan) {
  return submitted_setting(plan, "threads");
}

int status_exit_code(const std::vector<TaskStatus>& states) {
  bool failed = false, queued = false, unsubmitted = false;
  for (const TaskStatus& st : states) {
    failed |= st.state == TaskState::kFailed || st.state == TaskState::kNotRun;
    queued |= st.state == TaskState::kPending || st.state == TaskState::kRunning;
    unsubmitted |= st.state == TaskState::kNotSubmitted;
  }
  return failed ? 4 : queued ? 3 : unsubmitted ? 5 : 0;
}

std::string status_json(const Plan& plan, const std::vector<TaskStatus>& states) {
  // Logs and Slurm's reasons are any bytes: their bad UTF-8 is marked, never an error.
  const auto text = [](const std::string& s) {
    return s.empty() ? std::string("null") : shot::json_string(valid_utf8_or_marks(s), "status");
  };
  std::string out = "[\n";
  for (std::size_t i = 0; i < states.size(); ++i) {
    const TaskStatus& st = states[i];
    const Task& t = *st.task;
    out += fmt::format(
        "  {{\"task\": {}, \"shot\": {}, \"kind\": \"{}\", \"layer\": {}, \"frames\": [{}, {}], "
        "\"state\": \"{}\", \"job\": {}, \"exit\": {}, \"log\": {}, \"error\": {}, "
        "\"detail\": {}}}{}\n",
        text(t.id), text(plan.shots[std::size_t(t.shot)].name), shot::task_kind_name(t.kind),
        text(t.layer), t.first_frame, t.last_frame, task_state_name(st.state), text(st.job),
        st.exit_code ? std::to_string(*st.exit_code) : "null", text(st.log), text(st.error_line),
        text(st.detail), i + 1 < states.size() ? "," : "");
  }
  return out + "]\n";
}

std::string slurm_failure(const std::string& tool, int exit_code, const std::string& err) {
  if (exit_code < 0 && err.empty())
    return fmt::format("could not run {}: Slurm's commands are not installed here (not on PATH)",
                       tool);
  const auto has = [&err](const char* s) { return err.find(s) != std::string::npos; };
  if (has("configuration source") || has("slurm.conf") || has("fetch_config"))
    return fmt::format(
        "Slurm is not configured on this machine ({} finds no slurm.conf: set "
        "SLURM_CONF to the cluster's)",
        tool);
  if (has("Unable to contact slurm controller") || has("Unable to contact slurmctld") ||
      has("connect failure") || has("Connection refused"))
    return fmt::format("the Slurm controller does not answer ({}: {}); is slurmctld running?", tool,
                       first_line(err));
  return fmt::format("{} failed ({}): {}", tool, exit_code, first_line(err));
}

int cancel(const Plan& plan) {
  const auto q = queue();
  std::map<std::string, std::string> jobs;
  for (int s = 0; s < int(plan.shots.size()); ++s) jobs.merge(queued_jobs(plan, s, q));
  if (jobs.empty()) return 0;
  scancel(jobs);
  return int(jobs.size());
}

}  // namespace emaki::farm
