// Fuzzes `emaki synth`'s argument parser: the input is the argument list, one argument per
// line. Errors (emaki::Error) are the expected answer to bad arguments; anything else that
// escapes, and every sanitizer report, is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "apps/emaki/synth_args.h"
#include "core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> args;
  std::string cur;
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      args.push_back(cur);
      cur.clear();
    } else {
      cur += char(data[i]);
    }
  }
  if (!cur.empty()) args.push_back(cur);
  try {
    const emaki::app::SynthArgs a = emaki::app::parse_synth_args(args);
    // Accepted counts stay within the documented bounds.
    if (a.params.patch_size > emaki::app::kMaxPatchSize ||
        a.params.search_vote_iters > emaki::app::kMaxIterations ||
        a.params.patch_match_iters > emaki::app::kMaxIterations ||
        a.params.pyramid_levels > emaki::app::kMaxPyramidLevels ||
        a.guides.size() > size_t(emaki::app::kMaxGuides))
      __builtin_trap();
  } catch (const emaki::Error&) {
  }
  return 0;
}
