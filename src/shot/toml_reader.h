// Reading one TOML table of a shot file against the schema (shot/schema.h): its known keys, each
// number's range, typed choices (shot/kinds.h), and errors that name the key path. Internal to
// the shot module.
#pragma once

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "composite/composite.h"
#include "core/error.h"
#include "core/limits.h"
#include "shot/kinds.h"
#include "shot/schema.h"

namespace emaki::shot {

// Levenshtein edit distance, and the closest of `candidates` to `key` if it is close enough to
// be a likely typo (empty otherwise).
int edit_distance(std::string_view a, std::string_view b);
std::string closest_key(std::string_view key, const std::vector<std::string>& candidates);

const char* type_name(const toml::node& n);
std::string join_quoted(const std::vector<std::string>& v);

class Reader {
 public:
  // Scene units, pixels, degrees and seconds beyond this are typos or attacks, and their
  // squares would overflow a float. It bounds every number the schema gives no range.
  static constexpr double kMaxMagnitude = 1e9;

  // `path`: the table's key path as the user wrote it ("layers.outline"); `schema_prefix`: the
  // same in the schema ("layers.NAME"). Unknown keys are reported first: a typo explains the
  // errors that would follow from it.
  Reader(const toml::table& table, std::string path, std::string schema_prefix);
  // A table whose keys are names from `known` (pass names), each specified by the schema's
  // `schema_prefix`.`wildcard` ("layers.NAME.guides" . "PASS").
  Reader(const toml::table& table, std::string path, std::string schema_prefix,
         std::vector<std::string> known, std::string wildcard);

  // Keys come from the file: an unknown one may be megabytes long, so it is echoed capped.
  std::string key_path(std::string_view key) const {
    return path_.empty() ? echo(key) : path_ + "." + echo(key);
  }
  const std::string& path() const { return path_; }

  const toml::node* node(std::string_view key) const;
  bool has(std::string_view key) const { return node(key) != nullptr; }
  [[noreturn]] void type_error(std::string_view key, const toml::node& n,
                               const char* expected) const;

  // A finite number within the schema's range for `key` (+-kMaxMagnitude if it gives none).
  double number(std::string_view key, double fallback) const;
  float real(std::string_view key, float fallback) const { return float(number(key, fallback)); }
  // An integer within the schema's range (int32 if it gives none), compared as int64: a double
  // would round 2^53 + 1.
  int64_t integer64(std::string_view key, int64_t fallback) const;
  int integer(std::string_view key, int fallback) const { return int(integer64(key, fallback)); }
  bool boolean(std::string_view key, bool fallback) const;
  std::string string(std::string_view key, const std::string& fallback) const;
  // A string naming one of `names`; an unknown name is an error suggesting the closest.
  template <typename E, std::size_t N>
  E choice(std::string_view key, E fallback, const Named<E> (&names)[N]) const {
    if (!has(key)) return fallback;
    const std::string s = string(key, "");
    for (const Named<E>& n : names)
      if (n.name == s) return n.value;
    choice_error(key, s, names_of(names));
  }
  // An array of exactly `count` numbers (count < 0: any length >= 1), each finite and within
  // +-kMaxMagnitude.
  std::vector<float> numbers(std::string_view key, int count) const;
  composite::Color color(std::string_view key, composite::Color fallback) const;
  glm::vec3 vec3(std::string_view key, glm::vec3 fallback) const;
  const toml::table* table(std::string_view key, bool required = false) const;

 private:
  void check_unknown_keys() const;
  [[noreturn]] void choice_error(std::string_view key, const std::string& value,
                                 const std::vector<std::string>& options) const;
  const KeySpec& spec(std::string_view key) const;

  const toml::table& table_;
  std::string path_, prefix_, wildcard_;
  std::vector<std::string> known_;
};

// Where relative paths in a shot file lead: its folder.
struct PathContext {
  std::filesystem::path base;
  std::string resolve(const std::string& p) const;
  // A path key naming an input file that must exist.
  std::string input_file(const Reader& r, std::string_view key, bool required) const;
};

// The names of render/passes.h's passes.
std::vector<std::string> pass_names();

}  // namespace emaki::shot
