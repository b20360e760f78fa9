// End-to-end tests of `emaki plan`, `emaki farm submit --dry-run` and `emaki task` on hostile
// names: a one-line error and a non-zero exit, or output that holds up (valid JSON, a shot file
// named like an option), never a command run from a file's text or a silent success.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "core/version.h"
#include "tests/cli_run.h"
#include "tests/small_painting.h"

namespace fs = std::filesystem;
using namespace emaki;

namespace {

const std::string kData = EMAKI_TEST_DATA;

int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

class FarmCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_farm_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    test::write_small_painting(kData + "/stylit/source_style.png", (dir_ / "p.png").string());
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A two-frame shot file `name` in the test folder; `folder` and `layer` are TOML text.
  fs::path write_shot(const std::string& name, const std::string& folder,
                      const std::string& layer = "base") const {
    const fs::path path = dir_ / name;
    std::ofstream(path) << "[source]\nscene = \"" << kData
                        << "/scenes/Fox.glb\"\nclip = \"Walk\"\nframes = [0, 1]\n"
                        << "size = [32, 20]\naa = 1\n[exemplars.sphere]\npainting = \""
                        << (dir_ / "p.png").string() << "\"\n[layers." << layer
                        << "]\nkind = \"base\"\nexemplar = \"sphere\"\n[outputs]\nfolder = \""
                        << folder << "\"\nmp4 = false\n";
    return path;
  }
  test::CliResult emaki(const std::vector<std::string>& args) const {
    test::CliOptions o;
    o.cwd = dir_;
    return test::run_cli(EMAKI_BINARY, args, o);
  }
  // A one-line error naming `subject`, and a non-zero exit.
  static void expect_error(const test::CliResult& r, const std::string& subject) {
    EXPECT_NE(r.exit_code, 0) << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(subject), std::string::npos) << r.err;
  }
  fs::path dir_;
};

// A newline in outputs.folder (a TOML escape) or in the file name would end a script line and
// run the rest on the node.
TEST_F(FarmCli, ANewlineInAFolderOrAFileNameIsAOneLineError) {
  const fs::path a = write_shot("a.toml", (dir_ / "out\\ntouch pwned\\n").string());
  expect_error(emaki({"farm", "submit", "--dry-run", a.string()}), "outputs.folder");
  const fs::path b = write_shot("b\ntouch pwned\n.toml", (dir_ / "out").string());
  expect_error(emaki({"farm", "submit", "--dry-run", b.string()}), "a newline");
  EXPECT_FALSE(fs::exists(dir_ / "pwned"));
}

TEST_F(FarmCli, DryRunScriptsQuoteTheFolderAndKeepItOutOfDirectives) {
  const std::string folder = (dir_ / "my out $(touch pwned) 50%j").string();
  const test::CliResult r =
      emaki({"farm", "submit", "--dry-run", write_shot("a.toml", folder).string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("FARM='" + folder + "/farm'\n"), std::string::npos) << r.out;
  std::size_t at = 0;
  while ((at = r.out.find("#SBATCH", at)) != std::string::npos) {
    const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
    EXPECT_EQ(line.find("my out"), std::string::npos) << line;
    EXPECT_EQ(line.find(' '), 7u) << line;  // "#SBATCH --key=value": one blank
    ++at;
  }
  EXPECT_FALSE(fs::exists(dir_ / "pwned"));
}

TEST_F(FarmCli, PartitionThatADirectiveCannotHoldIsAnError) {
  const fs::path a = write_shot("a.toml", (dir_ / "out").string());
  expect_error(emaki({"farm", "submit", "--dry-run", a.string(), "--partition", "gpu --uid=0"}),
               "--partition");
}

// `plan --json` prints JSON a parser accepts, or refuses a name JSON cannot carry.
TEST_F(FarmCli, PlanJsonIsValidOrAnError) {
  const fs::path ok = write_shot("caf\xc3\xa9 \"q\" \\.toml", (dir_ / "out1").string());
  const test::CliResult r = emaki({"plan", "--json", ok.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ofstream(dir_ / "plan.json") << r.out;
  const std::string check =
      "/usr/bin/python3 -c 'import json,sys; json.load(open(sys.argv[1]))' '" +
      (dir_ / "plan.json").string() + "'";
  EXPECT_EQ(std::system(check.c_str()), 0) << r.out;
  const fs::path latin1 = write_shot("caf\xe9.toml", (dir_ / "out2").string());
  const test::CliResult bad = emaki({"plan", "--json", latin1.string()});
  expect_error(bad, "is not UTF-8");
}

// d1/a.toml, d2/a.toml and a-2.toml: three shots, three sets of task ids.
TEST_F(FarmCli, ShotsWithOneStemPlanApart) {
  fs::create_directories(dir_ / "d1");
  fs::create_directories(dir_ / "d2");
  const test::CliResult r = emaki({"plan", write_shot("d1/a.toml", (dir_ / "o1").string()).string(),
                                   write_shot("d2/a.toml", (dir_ / "o2").string()).string(),
                                   write_shot("a-2.toml", (dir_ / "o3").string()).string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::set<std::string> ids;
  std::size_t at = r.out.find('\n') + 1;
  while (at < r.out.size()) {
    const std::string id = r.out.substr(at, r.out.find(' ', at) - at);
    EXPECT_TRUE(ids.insert(id).second) << id;
    at = r.out.find('\n', at) + 1;
  }
  EXPECT_EQ(ids.size(), 3u * 5u) << r.out;
}

TEST_F(FarmCli, AnEmptyLayerNameIsAOneLineError) {
  const fs::path a = write_shot("a.toml", (dir_ / "out").string(), "\"\"");
  expect_error(emaki({"plan", a.string()}), "layers.\"\": a layer needs a name");
}

// A shot file named like an option needs no "--".
TEST_F(FarmCli, AShotFileNamedLikeAnOptionIsAFile) {
  write_shot("-x.toml", (dir_ / "out").string());
  const test::CliResult r = emaki({"plan", "-x.toml"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("-x-"), std::string::npos) << r.out;
  const test::CliResult dry = emaki({"farm", "submit", "--dry-run", "-x.toml"});
  EXPECT_EQ(dry.exit_code, 0) << dry.err;
  EXPECT_NE(dry.out.find("'" + (dir_ / "-x.toml").string() + "'"), std::string::npos);
}

TEST_F(FarmCli, PreviewsOfAnUnpreparedFolderAreAnError) {
  const fs::path a = write_shot("a.toml", (dir_ / "out").string());
  expect_error(emaki({"task", "previews", a.string()}), (dir_ / "out").string());
}

// A task's log (its stdout and stderr, docs/farm.md) starts with the version that ran it.
TEST_F(FarmCli, ATaskLogStartsWithTheVersion) {
  const fs::path a = write_shot("a.toml", (dir_ / "out").string());
  const test::CliResult r = emaki({"task", "prepare", a.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, std::string("emaki task: emaki ") + version() + "\n");
}

TEST_F(FarmCli, FarmHelpExitsZero) {
  const test::CliResult r = emaki({"farm", "--help"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("status"), std::string::npos) << r.out;
}

// Slurm's client without a configuration (no SLURM_CONF, no slurm.conf) says so in many lines;
// emaki says it in one.
TEST_F(FarmCli, SlurmWithoutAConfigurationIsAOneLineError) {
  fs::create_directories(dir_ / "bin");
  std::ofstream(dir_ / "bin/squeue")
      << "#!/bin/sh\necho 'squeue: error: resolve_ctls_from_dns_srv: res_nsearch error: Unknown "
         "host' >&2\necho 'squeue: fatal: Could not establish a configuration source' >&2\n"
         "exit 1\n";
  fs::permissions(dir_ / "bin/squeue", fs::perms::owner_all, fs::perm_options::add);
  const fs::path shot = write_shot("a.toml", "out");
  test::CliOptions o;
  o.cwd = dir_;
  o.env = {"PATH=" + (dir_ / "bin").string() + ":/usr/bin:/bin"};
  for (const char* command : {"status", "cancel"}) {
    const test::CliResult r = test::run_cli(EMAKI_BINARY, {"farm", command, shot.string()}, o);
    expect_error(r, "not configured");
  }
}

}  // namespace
