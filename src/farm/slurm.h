// The plan (shot/plan.h) on Slurm: one job array per (shot, task kind) with the tasks still to
// do, each array `--dependency=afterok` on the arrays holding the tasks it waits for, job ids
// recorded in the shot's output folder (farm/jobs.tsv), logs per task (farm/logs/TASK.log) and
// each task's exit code (farm/status/TASK.exit). Shared storage is assumed: every node sees the
// shot files, their inputs and the output folders under the same paths. Text from shot files and
// options reaches a script only through farm/script_text.h; what is read back from the farm
// folder and the queue goes through farm/farm_state.h.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "shot/plan.h"

namespace emaki::farm {

struct SlurmOptions {
  std::string partition, account, time;  // sbatch's --partition, --account, --time when set
  bool dry_run = false;                  // print the scripts; submit nothing, write nothing
};

struct SubmittedArray {
  std::string job;   // Slurm's job id
  std::string name;  // its job name, emaki:SHOT:STAGE
  int tasks = 0;
};

struct Submitted {
  std::vector<std::string> scripts;    // dry run: the scripts' text; else their paths
  std::vector<SubmittedArray> arrays;  // what was queued, in submission order (none in a dry run)
  int jobs = 0;                        // job arrays submitted
  int tasks = 0;                       // tasks in them
  int done = 0;                        // tasks left out as finished already
};

// Submits the plan's unfinished tasks, each array as `sbatch --chdir=OUTPUT/farm`. Throws
// emaki::Error naming a shot file when that shot still has jobs in the queue, the value a script
// cannot carry (script_text.h), the failing command when sbatch refuses a script, or jobs.tsv
// when an array's records cannot be written (that array is then cancelled, no other submitted).
Submitted submit(const shot::Plan& plan, const SlurmOptions& options);

// A batch script for `tasks` (one array; all of one shot); `depends` are job ids. Throws
// emaki::Error naming the shot file, its outputs.folder or the option holding text a script
// cannot carry.
std::string batch_script(const shot::Plan& plan, const std::vector<const shot::Task*>& tasks,
                         const std::vector<std::string>& depends, const SlurmOptions& options);

enum class TaskState { kDone, kRunning, kPending, kFailed, kNotRun, kNotSubmitted };
const char* task_state_name(TaskState s);

struct TaskStatus {
  const shot::Task* task = nullptr;
  TaskState state = TaskState::kNotSubmitted;
  std::string job;     // "JOBID_INDEX"
  std::string detail;  // a failed task's exit code, log and error line; a pending task's reason
  std::optional<int> exit_code;  // the task's recorded exit code, when it finished
  std::string log;               // its log, when it ran (or started)
  std::string error_line;        // a failed task's log's error line
};

// `emaki farm status`'s exit code for these states: 0 every task done, 3 none failed and some
// still pending or running, 4 some failed or left the queue without running, 5 none of those
// but some never submitted.
int status_exit_code(const std::vector<TaskStatus>& states);

// The states as JSON: an array of one object per task (task, shot, kind, layer, frames, state,
// job, exit, log, error, detail).
std::string status_json(const shot::Plan& plan, const std::vector<TaskStatus>& states);

// Every task's state, from the queue (the user's own jobs, under the shot's own job names), the
// exit codes and the outputs on disk.
std::vector<TaskStatus> status(const shot::Plan& plan);

// The chunk (`--chunk`) the plan's shots were last submitted with, recorded by submit in
// farm/chunk: status must plan with it, for task ids name their frames. Empty when no shot was
// submitted. Throws emaki::Error naming a shot's record when it is not a chunk, or the field
// "chunk" when the shots were submitted with different chunks.
std::optional<int> submitted_chunk(const shot::Plan& plan);
// The same for the threads per task (`--threads`), recorded in farm/threads.
std::optional<int> submitted_threads(const shot::Plan& plan);

// Slurm's command-line tool `tool` failed with `r`: one line saying why in a user's terms (Slurm
// not installed, not configured, its controller unreachable), else the tool's first line.
std::string slurm_failure(const std::string& tool, int exit_code, const std::string& err);

// Cancels every queued job recorded for the plan's shots that is the user's and carries the
// shot's own job name (scancel --user --name). Returns the job arrays cancelled.
int cancel(const shot::Plan& plan);

}  // namespace emaki::farm
