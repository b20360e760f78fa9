// `emaki --version`, `emaki version`, and every command's --help: what the man page is made of
// (cmake/man_page.cmake), so each must answer on stdout with exit 0.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "core/version.h"
#include "tests/cli_run.h"

namespace {

using emaki::test::CliResult;
using emaki::test::run_cli;

CliResult emaki_cli(const std::vector<std::string>& args) {
  return run_cli(EMAKI_BINARY, args, {});
}

TEST(VersionCli, VersionOptionAndCommandPrintTheBuildsVersion) {
  const std::string want = std::string("emaki ") + emaki::version() + "\n";
  for (const char* spelling : {"--version", "version"}) {
    const CliResult r = emaki_cli({spelling});
    EXPECT_EQ(r.exit_code, 0) << spelling << ": " << r.err;
    EXPECT_EQ(r.out, want) << spelling;
  }
  EXPECT_EQ(std::string(emaki::version()).rfind(emaki::project_version(), 0), 0u);
}

// The commands `emaki --help` lists: lines "  NAME  summary".
std::vector<std::string> listed_commands() {
  std::vector<std::string> names;
  std::istringstream in(emaki_cli({"--help"}).out);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("  ", 0) == 0 && line.size() > 2 && line[2] != ' ')
      names.push_back(line.substr(2, line.find(' ', 2) - 2));
  return names;
}

TEST(VersionCli, EveryCommandAnswersHelpWithExitZero) {
  const std::vector<std::string> names = listed_commands();
  EXPECT_GE(names.size(), 10u);
  for (const std::string& name : names) {
    const CliResult r = emaki_cli({name, "--help"});
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_FALSE(r.out.empty()) << name;
  }
}

}  // namespace
