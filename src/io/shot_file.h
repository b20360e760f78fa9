// The shot file: TOML (toml++) into a pipeline::Shot. Every key is documented in
// docs/shot_file.md; a key that nothing reads is an error with a "did you mean" suggestion, and
// every error names its key path (e.g. "layers.outline.wieght: unknown key — did you mean
// 'weight'?"). Relative paths are resolved against the shot file's folder.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "pipeline/shot.h"

namespace emaki::io {

// Parses and checks a shot file: syntax, keys, types, ranges, references between sections,
// input files that must exist, and that the output folder can be written. Throws emaki::Error.
pipeline::Shot load_shot(const std::string& path);

// The same from text (`path` is used for messages and to resolve relative paths).
pipeline::Shot parse_shot(std::string_view text, const std::string& path);

// Levenshtein edit distance, and the closest of `candidates` to `key` if it is close enough to
// be a likely typo (empty otherwise).
int edit_distance(std::string_view a, std::string_view b);
std::string closest_key(std::string_view key, const std::vector<std::string>& candidates);

}  // namespace emaki::io
