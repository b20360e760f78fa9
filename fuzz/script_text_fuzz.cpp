// Fuzzes the batch-script quoting (src/farm/script_text.h). The first byte picks the function,
// the rest is the value. What is accepted must read back exactly: a shell word unquotes (by the
// POSIX single-quote rules) to the value and holds no line break; a directive value holds only
// letters, digits and its allowed characters; a Slurm pattern literal undoubles to the value; a
// job name part has only safe bytes. Refusals are
// emaki::Error; anything else that escapes, and every sanitizer report, is a bug.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/error.h"
#include "farm/script_text.h"

namespace {

// A word of single-quoted parts and \' between them, as sh reads it; "\x01" when it is not one.
std::string unquote(const std::string& word) {
  std::string out;
  std::size_t i = 0;
  while (i < word.size()) {
    if (word[i] == '\'') {
      const std::size_t end = word.find('\'', i + 1);
      if (end == std::string::npos) return "\x01";
      out += word.substr(i + 1, end - i - 1);
      i = end + 1;
    } else if (word.compare(i, 2, "\\'") == 0) {
      out += '\'';
      i += 2;
    } else {
      return "\x01";
    }
  }
  return out;
}

bool plain(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string value(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 4) {
      case 0: {
        const std::string word = emaki::farm::shell_word(value, "fuzz");
        if (word.find_first_of(std::string("\n\r\0", 3)) != std::string::npos) __builtin_trap();
        if (unquote(word) != value) __builtin_trap();
        break;
      }
      case 1: {
        constexpr std::string_view allowed = "._-:,";
        const std::string v = emaki::farm::directive_value(value, "fuzz", allowed);
        if (v != value || v.empty() || v[0] == '-') __builtin_trap();
        for (const char c : v)
          if (!plain(c) && allowed.find(c) == std::string_view::npos) __builtin_trap();
        break;
      }
      case 2: {
        // Undoubling the % gives the value back; no lone % is left to expand.
        const std::string pattern = emaki::farm::slurm_pattern_literal(value, "fuzz");
        std::string back;
        for (std::size_t i = 0; i < pattern.size(); ++i) {
          if (pattern[i] == '%' && (i + 1 == pattern.size() || pattern[++i] != '%'))
            __builtin_trap();
          back += pattern[i];
        }
        if (back != value || value.find('\\') != std::string::npos) __builtin_trap();
        break;
      }
      default: {
        const std::string name = emaki::farm::job_name_part(value);
        if (name.size() != value.size()) __builtin_trap();
        for (const char c : name)
          if (!plain(c) && c != '.' && c != '_' && c != '-') __builtin_trap();
        emaki::farm::directive_value("emaki:" + name, "fuzz", "._-:");
      }
    }
  } catch (const emaki::Error&) {
  }
  return 0;
}
