// The one quoting / validation path from shot files and options into batch scripts: each class
// of text a script cannot carry is refused with an error naming its subject, and what is taken
// reads back as exactly the value (checked by running /bin/sh on the quoted word).
#include "farm/script_text.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/error.h"

namespace emaki::farm {
namespace {

// What /bin/sh prints for `printf %s WORD`: the word as the shell reads it back.
std::string shell_reads(const std::string& word) {
  const std::string command = "printf %s " + word;
  std::string quoted_command = "'";
  for (const char c : command)
    quoted_command += c == '\'' ? std::string("'\\''") : std::string(1, c);
  quoted_command += "'";
  FILE* p = ::popen(("/bin/sh -c " + quoted_command).c_str(), "r");
  std::string out;
  char buf[256];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  ::pclose(p);
  return out;
}

// The message of the Error `f` throws, or "" when it throws none.
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "outputs.folder");
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.message();
  }
  return "";
}

TEST(ScriptText, ShellWordsReadBackAsTheValue) {
  for (const std::string v :
       {"plain", "with space", "it's", "\"double\"", "$(touch pwned)", "`touch pwned`", "50%j_%A",
        "-x.toml", "a\\b", "$HOME ${X}", "*?[a]", ";&|<>", "caf\xc3\xa9 \xe2\x9c\x93", "", "'''"}) {
    EXPECT_EQ(shell_reads(shell_word(v, "outputs.folder")), v) << v;
  }
  EXPECT_EQ(shell_word("it's", "x"), "'it'\\''s'");
}

TEST(ScriptText, ControlCharactersAreRefused) {
  EXPECT_NE(error_of([] { shell_word("a\ntouch pwned", "outputs.folder"); }).find("a newline"),
            std::string::npos);
  EXPECT_NE(error_of([] { shell_word("a\rb", "outputs.folder"); }).find("a carriage return"),
            std::string::npos);
  EXPECT_NE(
      error_of([] { shell_word(std::string("a\0b", 3), "outputs.folder"); }).find("a NUL byte"),
      std::string::npos);
  EXPECT_NE(error_of([] { shell_word("a\tb", "outputs.folder"); }), "");
  EXPECT_NE(error_of([] { shell_word("a\x7f", "outputs.folder"); }), "");
}

TEST(ScriptText, NonUtf8IsRefused) {
  for (const std::string v :
       {"\xff", "a\xc3", "\xc0\xaf", "\xed\xa0\x80", "\xf4\x90\x80\x80", "\xe2\x82"})
    EXPECT_NE(error_of([&] { shell_word(v, "outputs.folder"); }).find("not UTF-8"),
              std::string::npos)
        << v;
  EXPECT_EQ(error_of([] { check_script_text("\xf0\x9f\x8e\xa8", "outputs.folder"); }), "");
}

TEST(ScriptText, DirectiveValuesTakeOnlyTheirCharacters) {
  EXPECT_EQ(directive_value("gpu-a100.x", "outputs.folder", "._-,"), "gpu-a100.x");
  EXPECT_EQ(directive_value("2-00:30:00", "outputs.folder", ":-"), "2-00:30:00");
  for (const std::string v : {"a b", "a'b", "a\"b", "$(id)", "`id`", "a%j", "a#b", "a\\b", "a=b"})
    EXPECT_NE(error_of([&] { directive_value(v, "outputs.folder", "._-,"); }).find("#SBATCH"),
              std::string::npos)
        << v;
  EXPECT_NE(error_of([] { directive_value("a b", "outputs.folder", "._-"); }).find("a space"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              directive_value("--wrap=id", "outputs.folder", "-=-");
            }).find("starts with '-'"),
            std::string::npos);
  EXPECT_NE(error_of([] { directive_value("a\nb", "outputs.folder", "._-"); }).find("newline"),
            std::string::npos);
  EXPECT_NE(error_of([] { directive_value("", "outputs.folder", "._-"); }), "");
}

TEST(ScriptText, PercentSignsAreDoubledInSlurmPatterns) {
  EXPECT_EQ(slurm_pattern_literal("/o/50%j %A x", "outputs.folder"), "/o/50%%j %%A x");
  EXPECT_EQ(slurm_pattern_literal("/o/%%", "outputs.folder"), "/o/%%%%");
  EXPECT_NE(error_of([] { slurm_pattern_literal("/o/a\\%j", "outputs.folder"); }).find("backslash"),
            std::string::npos);
  EXPECT_NE(error_of([] { slurm_pattern_literal("/o/a\nb", "outputs.folder"); }).find("newline"),
            std::string::npos);
}

TEST(ScriptText, JobNamesAreMadeFromAnyText) {
  EXPECT_EQ(job_name_part("sh010-1a2b"), "sh010-1a2b");
  EXPECT_EQ(job_name_part("a b\n$(x)%j\xff"), "a_b___x__j_");
  EXPECT_EQ(directive_value("emaki:" + job_name_part("-\"'`;%"), "outputs.folder", "._-:"),
            "emaki:-_____");
}

}  // namespace
}  // namespace emaki::farm
