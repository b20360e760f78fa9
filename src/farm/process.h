// Running a scheduler's command-line tools (sbatch, squeue, scancel) and reading what they print.
#pragma once

#include <string>
#include <vector>

namespace emaki::farm {

struct ProcessResult {
  int exit_code = -1;  // -1: could not start, or killed by a signal
  std::string out, err;
};

// Runs argv[0] (looked up on PATH) with /dev/null as its stdin; waits for it.
ProcessResult run_process(const std::vector<std::string>& argv);

}  // namespace emaki::farm
