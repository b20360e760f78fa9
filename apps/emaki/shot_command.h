// What the shot commands (run, composite, qa, task) share: the shot file, --frames, --threads,
// --max-memory and --no-previews bound to one shot::Request, and progress on stderr.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "apps/emaki/staging_options.h"
#include "pipeline/run.h"
#include "shot/api.h"

namespace emaki::app {

// A memory size in MB from "512", "512M", "8G" or "1T"; Error naming `option` otherwise.
int64_t parse_memory_mb(const std::string& option, const std::string& text);

// "a,b,,c" -> {"a", "b", "c"}.
std::vector<std::string> split_commas(const std::string& text);

// Progress on stderr: one updating line on a terminal, one line per step otherwise.
std::function<void(const pipeline::Progress&)> progress_printer(const char* command);
// Ends the updating line (on a terminal).
void end_progress_line();

struct ShotCommand {
  std::string shot_path, frames, layers;
  std::string max_memory;
  bool no_previews = false;
  bool request_maps = false;  // qa --maps: shot::Request::qa_maps
  int threads = -1;

  // The shot file, --frames (its help text given), --threads and --max-memory.
  void bind(CLI::App& app, const char* frames_help);
  void bind_previews(CLI::App& app);
  // The request; --frames is optional: empty leaves the shot's whole range.
  shot::Request request(const char* command) const;
};

}  // namespace emaki::app
