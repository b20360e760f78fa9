// The emaki subcommands. Each takes its arguments (after the subcommand name) and returns the
// process exit code; user errors are thrown as emaki::Error and printed once by main().
#pragma once

#include <string>
#include <vector>

namespace emaki::app {

using Args = std::vector<std::string>;

int run_synth(const Args& args);
int run_render(const Args& args);
int run_template(const Args& args);
int run_run(const Args& args);
int run_composite(const Args& args);
int run_qa(const Args& args);
int run_plan(const Args& args);
int run_farm(const Args& args);
int run_task(const Args& args);
int run_view(const Args& args);
int run_lookdev(const Args& args);
int run_version(const Args& args);

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const Args&);
};

// All subcommands, in the order `emaki --help` lists them.
const std::vector<Command>& commands();

}  // namespace emaki::app
