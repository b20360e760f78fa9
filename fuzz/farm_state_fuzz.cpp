// Fuzzes what `emaki farm` reads back from a shot's farm folder and from squeue
// (src/farm/farm_state.h): jobs.tsv records, farm/chunk, a task's exit code, squeue's lines.
// Bad text is an emaki::Error (or no exit code); what is accepted must be what emaki writes: job
// ids and indices decimal, chunks and exit codes in range. Anything else that escapes, and every
// sanitizer report, is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/limits.h"
#include "farm/farm_state.h"

namespace {

bool decimal_element(const std::string& s) {
  const std::size_t u = s.find('_');
  if (u == 0 || u == std::string::npos || u + 1 == s.size()) return false;
  return s.find_first_not_of("0123456789_") == std::string::npos &&
         s.find('_', u + 1) == std::string::npos;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    for (const auto& [task, element] : emaki::farm::parse_jobs(text, "jobs.tsv")) {
      if (task.empty() || !decimal_element(element)) __builtin_trap();
      // What parse_jobs accepts, job_record writes back the same.
      const std::size_t u = element.find('_');
      const std::string again = emaki::farm::job_record(task, element.substr(0, u), 0);
      if (emaki::farm::parse_jobs(again, "again").at(task) != element.substr(0, u) + "_0")
        __builtin_trap();
    }
  } catch (const emaki::Error&) {
  }
  try {
    const int chunk = emaki::farm::parse_chunk(text, "chunk");
    if (chunk < 1 || chunk > emaki::kMaxFrameCount) __builtin_trap();
  } catch (const emaki::Error&) {
  }
  if (const auto code = emaki::farm::parse_exit_code(text); code && (*code < 0 || *code > 255))
    __builtin_trap();
  for (const auto& [element, job] : emaki::farm::parse_queue(text)) {
    const std::string id = element.substr(0, element.find('_'));
    if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos ||
        element.find('_') == std::string::npos)
      __builtin_trap();
  }
  return 0;
}
