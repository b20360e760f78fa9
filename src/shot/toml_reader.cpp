#include "shot/toml_reader.h"

#include <cmath>

#include "core/check.h"
#include "io/input_file.h"
#include "render/passes.h"

namespace emaki::shot {

namespace fs = std::filesystem;

int edit_distance(std::string_view a, std::string_view b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = int(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = int(i);
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string closest_key(std::string_view key, const std::vector<std::string>& candidates) {
  std::string best;
  int best_d = 1 << 30;
  for (const std::string& c : candidates) {
    const int d = edit_distance(key, c);
    if (d < best_d) best_d = d, best = c;
  }
  // A typo changes a few letters; beyond a third of the word it is another word.
  const int limit = std::max<int>(2, int(key.size()) / 3);
  return best_d <= limit ? best : std::string();
}

const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date/time";
  }
}

std::string join_quoted(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "'" : ", '") + x + "'";
  return s;
}

Reader::Reader(const toml::table& table, std::string path, std::string schema_prefix)
    : table_(table),
      path_(std::move(path)),
      prefix_(std::move(schema_prefix)),
      known_(child_keys(prefix_)) {
  CHECK(!known_.empty());
  check_unknown_keys();
}

Reader::Reader(const toml::table& table, std::string path, std::string schema_prefix,
               std::vector<std::string> known, std::string wildcard)
    : table_(table),
      path_(std::move(path)),
      prefix_(std::move(schema_prefix)),
      wildcard_(std::move(wildcard)),
      known_(std::move(known)) {
  check_unknown_keys();
}

const KeySpec& Reader::spec(std::string_view key) const {
  const std::string full = prefix_.empty()     ? std::string(key)
                           : wildcard_.empty() ? prefix_ + "." + std::string(key)
                                               : prefix_ + "." + wildcard_;
  const KeySpec* k = find_key(full);
  CHECK(k != nullptr);
  return *k;
}

const toml::node* Reader::node(std::string_view key) const {
  CHECK(std::find(known_.begin(), known_.end(), key) != known_.end());
  return table_.get(key);
}

void Reader::type_error(std::string_view key, const toml::node& n, const char* expected) const {
  throw Error(key_path(key), fmt::format("expected {}, got {}", expected, type_name(n)));
}

// Every number must be finite and within its range: inf, nan or 1e300 in a camera value would
// otherwise render blank frames with exit 0.
double Reader::number(std::string_view key, double fallback) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  double v;
  if (auto i = n->value_exact<int64_t>())
    v = double(*i);
  else if (auto f = n->value_exact<double>())
    v = *f;
  else
    type_error(key, *n, "a number");
  if (!std::isfinite(v)) throw Error(key_path(key), fmt::format("must be finite, got {}", v));
  const KeySpec& k = spec(key);
  const double lo = std::isnan(k.lo) ? -kMaxMagnitude : k.lo;
  const double hi = std::isnan(k.hi) ? kMaxMagnitude : k.hi;
  if (!(v >= lo && v <= hi))
    throw Error(key_path(key), fmt::format("must be in [{}, {}], got {}", lo, hi, v));
  return v;
}

int64_t Reader::integer64(std::string_view key, int64_t fallback) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  auto i = n->value_exact<int64_t>();
  if (!i) type_error(key, *n, "an integer");
  const KeySpec& k = spec(key);
  const int64_t lo = std::isnan(k.lo) ? INT32_MIN : int64_t(k.lo);
  const int64_t hi = std::isnan(k.hi) ? INT32_MAX : int64_t(k.hi);
  if (*i < lo || *i > hi)
    throw Error(key_path(key), fmt::format("must be in [{}, {}], got {}", lo, hi, *i));
  return *i;
}

bool Reader::boolean(std::string_view key, bool fallback) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  auto b = n->value_exact<bool>();
  if (!b) type_error(key, *n, "true or false");
  return *b;
}

std::string Reader::string(std::string_view key, const std::string& fallback) const {
  const toml::node* n = node(key);
  if (!n) return fallback;
  auto s = n->value_exact<std::string>();
  if (!s) type_error(key, *n, "a string");
  return *s;
}

void Reader::choice_error(std::string_view key, const std::string& value,
                          const std::vector<std::string>& options) const {
  const std::string near = value.size() > 256 ? std::string() : closest_key(value, options);
  throw Error(key_path(key),
              fmt::format("'{}' is not one of {}{}", echo(value), join_quoted(options),
                          near.empty() ? "" : fmt::format(" — did you mean '{}'?", near)));
}

std::vector<float> Reader::numbers(std::string_view key, int count) const {
  const toml::node* n = node(key);
  CHECK(n != nullptr);
  const toml::array* a = n->as_array();
  const std::string expected =
      count > 0 ? fmt::format("an array of {} numbers", count) : std::string("an array of numbers");
  if (!a) type_error(key, *n, expected.c_str());
  std::vector<float> out;
  for (const toml::node& e : *a) {
    if (auto i = e.value_exact<int64_t>())
      out.push_back(float(*i));
    else if (auto f = e.value_exact<double>())
      out.push_back(float(*f));
    else
      throw Error(key_path(key),
                  fmt::format("expected {}, found {} in it", expected, type_name(e)));
    if (!std::isfinite(out.back())) throw Error(key_path(key), "values must be finite");
    if (std::abs(out.back()) > kMaxMagnitude)
      throw Error(key_path(key),
                  fmt::format("values must be within +-{}, got {}", kMaxMagnitude, out.back()));
  }
  if ((count > 0 && int(out.size()) != count) || out.empty())
    throw Error(key_path(key), fmt::format("expected {}, got {} value{}", expected, out.size(),
                                           out.size() == 1 ? "" : "s"));
  return out;
}

composite::Color Reader::color(std::string_view key, composite::Color fallback) const {
  if (!has(key)) return fallback;
  const std::vector<float> c = numbers(key, 3);
  for (float v : c)
    if (!(v >= 0.0f && v <= 1.0f))
      throw Error(key_path(key), fmt::format("colour components must be in [0, 1], got {}", v));
  return {c[0], c[1], c[2]};
}

glm::vec3 Reader::vec3(std::string_view key, glm::vec3 fallback) const {
  if (!has(key)) return fallback;
  const std::vector<float> c = numbers(key, 3);
  return {c[0], c[1], c[2]};
}

const toml::table* Reader::table(std::string_view key, bool required) const {
  const toml::node* n = node(key);
  if (!n) {
    if (required) throw Error(key_path(key), "is required");
    return nullptr;
  }
  const toml::table* t = n->as_table();
  if (!t) type_error(key, *n, "a table");
  return t;
}

void Reader::check_unknown_keys() const {
  for (const auto& [k, v] : table_) {
    const std::string key(k.str());
    if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
    const std::string near = closest_key(key, known_);
    throw Error(key_path(key), near.empty()
                                   ? fmt::format("unknown key (known: {})", join_quoted(known_))
                                   : fmt::format("unknown key — did you mean '{}'?", near));
  }
}

std::string PathContext::resolve(const std::string& p) const {
  if (p.empty()) return p;
  const fs::path path(p);
  return (path.is_absolute() ? path : base / path).lexically_normal().string();
}

std::string PathContext::input_file(const Reader& r, std::string_view key, bool required) const {
  const std::string raw = r.string(key, "");
  if (raw.empty()) {
    if (required) throw Error(r.key_path(key), "is required");
    return raw;
  }
  const std::string p = resolve(raw);
  if (const std::string problem = io::input_file_problem(p, echo_path(p)); !problem.empty())
    throw Error(r.key_path(key), problem);
  return p;
}

std::vector<std::string> pass_names() {
  std::vector<std::string> v;
  for (const auto& p : render::pass_table()) v.push_back(p.name);
  return v;
}

}  // namespace emaki::shot
