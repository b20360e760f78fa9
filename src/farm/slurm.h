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

struct Submitted {
  std::vector<std::string> scripts;  // dry run: the scripts' text; else their paths
  int jobs = 0;                      // job arrays submitted
  int tasks = 0;                     // tasks in them
  int done = 0;                      // tasks left out as finished already
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
};

// Every task's state, from the queue (the user's own jobs, under the shot's own job names), the
// exit codes and the outputs on disk.
std::vector<TaskStatus> status(const shot::Plan& plan);

// The chunk (`--chunk`) the plan's shots were last submitted with, recorded by submit in
// farm/chunk: status must plan with it, for task ids name their frames. Empty when no shot was
// submitted. Throws emaki::Error naming a shot's record when it is not a chunk, or the field
// "chunk" when the shots were submitted with different chunks.
std::optional<int> submitted_chunk(const shot::Plan& plan);

// Cancels every queued job recorded for the plan's shots that is the user's and carries the
// shot's own job name (scancel --user --name). Returns the job arrays cancelled.
int cancel(const shot::Plan& plan);

}  // namespace emaki::farm
