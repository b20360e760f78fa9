// A production as a task graph that any farm scheduler can run (the farm issue's plan): one or
// more shots, each as
//   prepare            check inputs, lock the folder alone, bring manifests up to date
//   passes  (chunks)   render guide passes once into the shot's pass cache (scene sources)
//   layer   (per layer; a layer without temporal advection in frame chunks: its frames are
//            independent; a temporal layer is one task, so its chain equals a one-machine run)
//   composite (chunks) after every layer task of the shot
//   previews           contact sheet and MP4, after every composite chunk
// Each task is an ordinary `emaki task ...` command line. Tasks already finished (the files
// `emaki run` would reuse, under current manifests) are marked done: submitting again re-runs
// only the rest. docs/farm.md documents the JSON form (plan_json).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/shot_description.h"
#include "shot/objects.h"

namespace emaki::shot {

enum class TaskKind { kPrepare, kPasses, kLayer, kComposite, kPreviews };
const char* task_kind_name(TaskKind kind);

struct Task {
  std::string id;  // unique in the plan: "SHOT.layer.base.0-7"
  int shot = 0;    // index into Plan::shots
  TaskKind kind = TaskKind::kPrepare;
  std::string layer;  // kLayer
  int first_frame = 0, last_frame = 0;
  std::vector<std::string> argv;     // the command line; argv[0] is the emaki binary
  std::vector<std::string> outputs;  // folders it writes, under the shot's output folder
  int64_t memory_mb = 0;             // estimated peak resident memory
  int threads = 1;
  std::vector<std::string> after;  // ids of tasks that must succeed first (none done)
  bool done = false;               // finished already: a submitter leaves it out
};

struct PlannedShot {
  std::string name;  // the shot file's stem, made unique in the plan
  std::string path;  // the shot file
  pipeline::Shot shot;
};

struct Plan {
  std::vector<PlannedShot> shots;
  std::vector<Task> tasks;  // in an order that respects `after`
  int chunk = 8;            // the options' chunk: task ids depend on it
  int threads = 1;          // the options' threads per task
};

struct PlanOptions {
  std::string emaki = "emaki";  // the binary the tasks run (an absolute path on a farm)
  int chunk = 8;                // frames per passes / layer / composite chunk, >= 1
  int threads = 1;              // threads per task (the scheduler's CPUs per task)
};

// A task's peak resident memory in MB, estimated from the frame size and the exemplars'
// paintings' pixels (their sum). `emaki run` and the tasks check it before their work
// (shot/memory.h); a plan gives it to the scheduler.
// `scene`: what the shot's scene holds (shot/objects.h; empty for studio passes).
int64_t task_memory_mb(const pipeline::Shot& s, double exemplar_pixels, TaskKind kind,
                       const SceneCost& scene = {});

// Plans the shots (each opened and checked by open()). Throws emaki::Error naming the shot file,
// or the field "chunk" / "threads" for bad options, or "shots" when two shots write one folder.
Plan plan(const std::vector<std::string>& shot_paths, const PlanOptions& options);
Plan plan(std::vector<PlannedShot> shots, const PlanOptions& options);

// The plan as JSON (docs/farm.md).
std::string plan_json(const Plan& plan);

// A JSON string. JSON is Unicode text: a value that is not UTF-8 (a path's raw bytes) cannot be
// carried faithfully, so it is an error naming `subject` and showing the text up to the bad byte.
std::string json_string(const std::string& s, const std::string& subject);

}  // namespace emaki::shot
