#include "farm/script_text.h"

#include <fmt/format.h>

#include "core/error.h"
#include "core/limits.h"
#include "core/utf8.h"

namespace emaki::farm {

namespace {

const char* control_name(unsigned char c) {
  switch (c) {
    case 0:
      return "a NUL byte";
    case '\n':
      return "a newline";
    case '\r':
      return "a carriage return";
    case '\t':
      return "a tab";
    default:
      return "a control character";
  }
}

bool ascii_alnum(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

}  // namespace

void check_script_text(std::string_view value, const std::string& subject) {
  for (std::size_t i = 0; i < value.size();) {
    const unsigned char c = static_cast<unsigned char>(value[i]);
    if (c < 0x20 || c == 0x7f)
      throw Error(subject, fmt::format("'{}' holds {} (byte {}), which a batch script cannot carry",
                                       echo(valid_utf8_or_marks(value)), control_name(c), i));
    const std::size_t n = utf8_sequence_length(value, i);
    if (n == 0)
      throw Error(subject, fmt::format("'{}...' is not UTF-8 text (byte {} is 0x{:02x}); a batch "
                                       "script cannot carry it",
                                       echo(value.substr(0, i)), i, unsigned(c)));
    i += n;
  }
}

std::string shell_word(std::string_view value, const std::string& subject) {
  check_script_text(value, subject);
  std::string out = "'";
  for (const char c : value) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  return out + "'";
}

std::string directive_value(std::string_view value, const std::string& subject,
                            std::string_view allowed) {
  check_script_text(value, subject);
  if (value.empty()) throw Error(subject, "is empty");
  if (value.front() == '-')
    throw Error(subject,
                fmt::format("'{}' starts with '-'; a Slurm option value cannot", echo(value)));
  for (const char c : value)
    if (!ascii_alnum(c) && allowed.find(c) == std::string_view::npos)
      throw Error(
          subject,
          fmt::format("'{}' holds '{}': an #SBATCH value may use letters, digits and "
                      "'{}' only",
                      echo(value), c == ' ' ? std::string("a space") : std::string(1, c), allowed));
  return std::string(value);
}

std::string slurm_pattern_literal(std::string_view value, const std::string& subject) {
  check_script_text(value, subject);
  if (value.find('\\') != std::string_view::npos)
    throw Error(subject, fmt::format("'{}' holds a backslash, which a Slurm --output path cannot",
                                     echo(value)));
  std::string out;
  for (const char c : value) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

std::string job_name_part(std::string_view text) {
  std::string out;
  for (const char c : text) out += ascii_alnum(c) || c == '.' || c == '_' || c == '-' ? c : '_';
  return out;
}

}  // namespace emaki::farm
