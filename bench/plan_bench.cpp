// Seconds to plan a long shot for a farm (`emaki plan`): examples/production/sh010.toml (two
// temporal layers, one chunked) with its frame range stretched, outputs in a folder that does
// not exist (every task to do), chunk 8. Prints the task-graph time and the JSON time per size;
// both should grow linearly in frames. Wall and CPU seconds are printed: on a shared machine the
// CPU time is the figure to compare.
//
//   plan_bench [FRAMES...]   (default: 100000 1000000, the documented limit)
#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "shot/api.h"
#include "shot/plan.h"

namespace {

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + double(t.tv_nsec) * 1e-9;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace emaki;
  using Clock = std::chrono::steady_clock;
  std::vector<int> sizes;
  for (int i = 1; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
  if (sizes.empty()) sizes = {100000, 1000000};
  try {
    const std::string path = std::string(EMAKI_SOURCE_DIR) + "/examples/production/sh010.toml";
    const pipeline::Shot base = shot::open(path);
    for (const int frames : sizes) {
      pipeline::Shot s = base;
      s.source.last_frame = s.source.shot.last_frame = s.source.first_frame + frames - 1;
      s.outputs.folder =
          (std::filesystem::temp_directory_path() / "emaki_plan_bench_none").string();
      shot::PlanOptions o;
      const auto t0 = Clock::now();
      const double c0 = cpu_seconds();
      const shot::Plan p = shot::plan(std::vector<shot::PlannedShot>{{"", path, s}}, o);
      const auto t1 = Clock::now();
      const double c1 = cpu_seconds();
      const std::string json = shot::plan_json(p);
      const auto t2 = Clock::now();
      const double c2 = cpu_seconds();
      std::size_t edges = 0;
      for (const shot::Task& t : p.tasks) edges += t.after.size();
      std::printf(
          "plan_bench: %d frames: %zu tasks, %zu dependencies: plan %.3f s (CPU %.3f s), "
          "json %.3f s (CPU %.3f s, %.1f MB)\n",
          frames, p.tasks.size(), edges, std::chrono::duration<double>(t1 - t0).count(), c1 - c0,
          std::chrono::duration<double>(t2 - t1).count(), c2 - c1, double(json.size()) / 1e6);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "plan_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
