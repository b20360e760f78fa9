// The shot file: TOML (toml++) into a pipeline::Shot. Every key is in the schema (shot/schema.h;
// docs/shot_file.md is made from it); a key that nothing reads is an error with a "did you mean"
// suggestion, and every error names its key path (e.g. "layers.outline.wieght: unknown key — did
// you mean 'weight'?"). Relative paths are resolved against the shot file's folder.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/shot_description.h"

namespace emaki::shot {

// A shot file is a page of text: larger files and deeper nesting are refused before toml++
// parses them (its parser recurses per level; see docs/shot_file.md, "Limits").
inline constexpr std::size_t kMaxShotBytes = 1 << 20;
inline constexpr int kMaxShotDepth = 64;

// Parses and checks a shot file: syntax, keys, types, ranges, references between sections,
// input files that must exist, and that the output folder can be written. Throws emaki::Error.
// A `limits.max_pixels` in the file is the shot's pixel budget (pipeline::Shot::max_pixels),
// applied while the file is parsed and during the shot's work (shot/api.h), unless the command
// line pinned one (--max-pixels); it never changes the budget of anything else.
pipeline::Shot load_shot(const std::string& path);

// The same from text (`path` is used for messages and to resolve relative paths).
pipeline::Shot parse_shot(std::string_view text, const std::string& path);

}  // namespace emaki::shot
