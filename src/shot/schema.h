// The shot file's schema: one table of every key (its type, default, range and meaning). The
// parser takes each table's known keys and each number's range from it, and docs/shot_file.md's
// key table is made from it (schema_markdown(); a test fails when the two differ).
#pragma once

#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace emaki::shot {

inline constexpr double kNoBound = std::numeric_limits<double>::quiet_NaN();

// One key. Path components NAME (a user's exemplar or layer name) and PASS (a pass name of
// render/passes.h) stand for any name.
struct KeySpec {
  std::string_view key;                 // "layers.NAME.uniformity"
  std::string_view type;                // as the docs show it: "number", "[int, int]", "table"
  std::string_view default_value;       // as the docs show it
  double lo = kNoBound, hi = kNoBound;  // a number's range, checked by the parser
  std::string_view range;               // shown instead of [lo, hi]: rules beyond a range
  std::string_view meaning;
  bool is_table() const { return type == "table"; }
};

std::span<const KeySpec> schema();

// The spec of `key` (with NAME / PASS placeholders); nullptr when the schema has no such key.
const KeySpec* find_key(std::string_view key);

// The keys directly under `prefix` ("" for the top level, "layers.NAME", "source.camera"), in
// table order.
std::vector<std::string> child_keys(std::string_view prefix);

// docs/shot_file.md's key table (Markdown, one row per key).
std::string schema_markdown();

}  // namespace emaki::shot
