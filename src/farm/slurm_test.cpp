// emaki farm against stand-ins for sbatch, squeue and scancel (shell scripts on PATH that log
// their arguments; the sbatch stand-in can run the array's script as a node would): hostile
// folder and file names never run a command, planted symlinks are not followed, the queue is
// read and cancelled only for the user's own jobs under the shot's own names, and a jobs.tsv
// that cannot be written stops the submission.
#include "farm/slurm.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "farm/farm_state.h"
#include "shot/api.h"
#include "tests/file_bytes.h"
#include "tests/small_painting.h"

namespace emaki::farm {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

void write_file(const fs::path& p, const std::string& text, bool executable = false) {
  std::ofstream(p, std::ios::binary) << text;
  if (executable) fs::permissions(p, fs::perms::owner_all, fs::perm_options::add);
}

class SlurmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_slurm_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "bin");
    test::write_small_painting(kData + "/stylit/source_style.png", painting());
    const std::string log = (dir_ / "log").string();
    fs::create_directories(log);
    // sbatch --parsable --chdir=DIR --output=PATTERN SCRIPT: logs, prints the next job id, and
    // with log/run present runs every element of the array from DIR as a node would.
    write_file(
        dir_ / "bin/sbatch",
        "#!/bin/sh\nprintf '%s\\n' \"$*\" >>'" + log + "/sbatch'\nn=$(cat '" + log +
            "/next' 2>/dev/null || echo 100)\n" + "echo $((n + 1)) >'" + log + "/next'\n" +
            "if [ -f '" + log +
            "/run' ]; then\n  last=$(sed -n 's/^#SBATCH --array=0-//p' \"$4\")\n" +
            "  i=0\n  while [ $i -le $last ]; do\n" +
            "    (cd \"${2#--chdir=}\" && SLURM_ARRAY_TASK_ID=$i sh \"$4\" >/dev/null 2>&1)\n" +
            "    i=$((i + 1))\n  done\nfi\necho $n\n",
        true);
    write_file(dir_ / "bin/squeue",
               "#!/bin/sh\nprintf '%s\\n' \"$*\" >>'" + log + "/squeue'\ncat '" + log +
                   "/queue' 2>/dev/null\nexit 0\n",
               true);
    write_file(dir_ / "bin/scancel",
               "#!/bin/sh\nprintf '%s\\n' \"$*\" >>'" + log + "/scancel'\nexit 0\n", true);
    // The task command: its arguments into its log.
    write_file(dir_ / "bin/emaki", "#!/bin/sh\nprintf '[%s]' \"$@\"\n", true);
    old_path_ = std::getenv("PATH");
    ::setenv("PATH", ((dir_ / "bin").string() + ":" + old_path_).c_str(), 1);
  }
  void TearDown() override {
    ::setenv("PATH", old_path_.c_str(), 1);
    fs::remove_all(dir_);
  }
  std::string painting() const { return (dir_ / "painting.png").string(); }
  std::string logged(const std::string& tool) const {
    return test::file_bytes(dir_ / "log" / tool);
  }

  // A two-frame shot written to FILE, its outputs in `folder` (TOML basic-string text, so
  // escapes such as \n are the file's own).
  shot::Plan plan_of(const std::string& file, const std::string& folder) const {
    const std::string text =
        "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nclip = \"Walk\"\nframes = [0, 1]\n" +
        "size = [32, 20]\naa = 1\n[exemplars.sphere]\npainting = \"" + painting() +
        "\"\n[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n[outputs]\nfolder = \"" +
        folder + "\"\nmp4 = false\n";
    const std::string path = (dir_ / file).string();
    write_file(path, text);
    shot::PlanOptions o;
    o.emaki = (dir_ / "bin/emaki").string();
    return shot::plan(std::vector<shot::PlannedShot>{{"", path, shot::open(path)}}, o);
  }

  // The batch script of the plan's first task, at DIR/prepare.sh, with its farm folder's status/
  // and logs/ made, as submit makes them.
  fs::path first_task_script(const shot::Plan& p) const {
    const std::string farm = p.shots[0].shot.outputs.folder + "/farm";
    for (const char* sub : {"/status", "/logs"}) fs::create_directories(farm + sub);
    const fs::path script = dir_ / "prepare.sh";
    write_file(script, batch_script(p, {&p.tasks.front()}, {}, {}));
    return script;
  }

  fs::path dir_;
  std::string old_path_;
};

// A newline (a TOML escape) in outputs.folder would end the script's line and run the rest.
TEST_F(SlurmTest, ANewlineInTheFolderIsAOneLineErrorAndNothingIsSubmitted) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out\\ntouch pwned\\n").string());
  for (const bool dry : {true, false}) {
    SlurmOptions o;
    o.dry_run = dry;
    try {
      submit(p, o);
      ADD_FAILURE() << "submitted";
    } catch (const Error& e) {
      EXPECT_NE(e.subject().find("outputs.folder"), std::string::npos) << e.what();
      EXPECT_NE(e.message().find("a newline"), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
  EXPECT_EQ(logged("sbatch"), "");
  EXPECT_FALSE(fs::exists(dir_ / "pwned"));
}

TEST_F(SlurmTest, ANewlineInTheShotFileNameIsAOneLineError) {
  const shot::Plan p = plan_of("a\ntouch pwned\n.toml", (dir_ / "out").string());
  SlurmOptions o;
  o.dry_run = true;
  try {
    submit(p, o);
    ADD_FAILURE() << "submitted";
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("a newline"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

// Quotes, $(), backticks, spaces, % and a leading '-' are all representable: the scripts run (by
// the sbatch stand-in, as a node would) and write their records in that very folder.
TEST_F(SlurmTest, HostileButRepresentableNamesRunNoCommand) {
  const std::string folder = "-o 'q' \\\"d\\\" $(touch pwned1) `touch pwned2` 50%j %A";
  fs::create_directories(dir_ / "work");
  const shot::Plan p = plan_of("-it's $(touch pwned3).toml", (dir_ / "work" / folder).string());
  write_file(dir_ / "log/run", "");
  const Submitted s = submit(p, {});
  EXPECT_EQ(s.jobs, 5);  // prepare, passes, layer, composite, previews
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name != "pwned1" && name != "pwned2" && name != "pwned3") << entry.path();
  }
  const std::string farm = p.shots[0].shot.outputs.folder + "/farm";
  ASSERT_TRUE(fs::is_directory(farm)) << farm;
  for (const shot::Task& t : p.tasks) {
    if (t.done) continue;
    EXPECT_EQ(read_state_file(farm + "/status/" + t.id + ".exit", 100), "0\n") << t.id;
    // The task ran with its arguments whole.
    const std::string log = test::file_bytes(farm + "/logs/" + t.id + ".log");
    EXPECT_NE(log.find("[" + p.shots[0].path + "]"), std::string::npos) << log;
  }
  // The folder's path only in sbatch's arguments, its % doubled in the --output pattern.
  std::string pattern = farm;
  for (std::size_t at = 0; (at = pattern.find('%', at)) != std::string::npos; at += 2)
    pattern.insert(at, "%");
  EXPECT_NE(
      logged("sbatch").find("--chdir=" + farm + " --output=" + pattern + "/logs/slurm-%A_%a.log "),
      std::string::npos)
      << logged("sbatch");
  for (const TaskStatus& st : status(p)) EXPECT_EQ(st.state, TaskState::kDone) << st.task->id;
}

TEST_F(SlurmTest, OptionsThatADirectiveCannotHoldAreRefused) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out").string());
  for (const auto& [partition, time] :
       {std::pair<std::string, std::string>{"gpu\n#SBATCH --wrap=id", ""},
        {"a b", ""},
        {"-x", ""},
        {"", "1:00 --uid=0"},
        {"", "$(id)"}}) {
    SlurmOptions o;
    o.dry_run = true;
    o.partition = partition;
    o.time = time;
    try {
      submit(p, o);
      ADD_FAILURE() << partition << time;
    } catch (const Error& e) {
      EXPECT_EQ(e.subject(), partition.empty() ? "--time" : "--partition");
    }
  }
  SlurmOptions ok;
  ok.dry_run = true;
  ok.partition = "gpu,cpu";
  ok.account = "film_01";
  ok.time = "1-02:00:00";
  const std::string script = submit(p, ok).scripts.at(0);
  EXPECT_NE(script.find("#SBATCH --partition=gpu,cpu\n"), std::string::npos);
  EXPECT_NE(script.find("#SBATCH --time=1-02:00:00\n"), std::string::npos);
}

// Links planted at a task's records (to files of the user's) are replaced, never written through.
TEST_F(SlurmTest, TheJobScriptDoesNotFollowPlantedSymlinks) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out").string());
  const shot::Task& t = p.tasks.front();
  const std::string farm = p.shots[0].shot.outputs.folder + "/farm";
  const fs::path script = first_task_script(p);
  std::vector<fs::path> victims;
  for (const std::string& record :
       {"/status/" + t.id + ".start", "/status/" + t.id + ".end", "/status/" + t.id + ".exit",
        "/status/" + t.id + ".exit.tmp", "/logs/" + t.id + ".log"}) {
    victims.push_back(dir_ / ("victim" + std::to_string(victims.size())));
    write_file(victims.back(), "precious\n");
    fs::create_symlink(victims.back(), farm + record);
  }
  const std::string run = "cd '" + farm + "' && SLURM_ARRAY_TASK_ID=0 sh '" + script.string() + "'";
  EXPECT_EQ(std::system(run.c_str()), 0);
  for (const fs::path& v : victims) EXPECT_EQ(test::file_bytes(v), "precious\n") << v;
  for (const char* ext : {".start", ".end", ".exit"})
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(farm + "/status/" + t.id + ext))) << ext;
  EXPECT_EQ(test::file_bytes(farm + "/status/" + t.id + ".exit"), "0\n");
  EXPECT_NE(test::file_bytes(farm + "/logs/" + t.id + ".log").find("[prepare]"), std::string::npos);
}

// Each task starts once: the script names glibc's huge-page tunable, which emaki would otherwise
// start itself again to add; a setting the submitting environment makes stays as it is.
TEST_F(SlurmTest, TheJobScriptNamesTheHugePageTunableUnlessTheUserDid) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out").string());
  const shot::Task& t = p.tasks.front();
  const std::string farm = p.shots[0].shot.outputs.folder + "/farm";
  const fs::path script = first_task_script(p);
  write_file(dir_ / "bin/emaki", "#!/bin/sh\nprintf '%s' \"$GLIBC_TUNABLES\"\n", true);
  for (const auto& [given, seen] : std::vector<std::pair<std::string, std::string>>{
           {"", "glibc.malloc.hugetlb=1"},
           {"glibc.malloc.tcache_count=0", "glibc.malloc.tcache_count=0:glibc.malloc.hugetlb=1"},
           {"glibc.malloc.hugetlb=0", "glibc.malloc.hugetlb=0"},
           {"glibc.malloc.check=0:glibc.malloc.hugetlb=2",
            "glibc.malloc.check=0:glibc.malloc.hugetlb=2"}}) {
    const std::string env =
        given.empty() ? "unset GLIBC_TUNABLES; " : "GLIBC_TUNABLES='" + given + "' ";
    const std::string run =
        "cd '" + farm + "' && " + env + "SLURM_ARRAY_TASK_ID=0 sh '" + script.string() + "'";
    EXPECT_EQ(std::system(run.c_str()), 0);
    EXPECT_EQ(test::file_bytes(farm + "/logs/" + t.id + ".log"), seen) << given;
  }
}

// A jobs.tsv copied from another shot (or stale) names jobs that are not this shot's: squeue is
// asked for the user's jobs only, and only jobs under the shot's own job names count or are
// cancelled.
TEST_F(SlurmTest, StatusAndCancelTouchOnlyTheUsersJobsUnderTheShotsNames) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out").string());
  const std::string farm = p.shots[0].shot.outputs.folder + "/farm";
  fs::create_directories(farm);
  const std::string prepare = p.tasks[0].id, passes = p.tasks[1].id;
  write_file(farm + "/jobs.tsv", job_record(prepare, "300", 0) + job_record(passes, "400", 0));
  const std::string own = "emaki:" + p.shots[0].name + ":prepare";
  write_file(dir_ / "log/queue",
             "300_0|RUNNING|None|" + own + "\n400_0|RUNNING|None|someone-elses-job\n");
  const std::vector<TaskStatus> st = status(p);
  EXPECT_EQ(st[0].state, TaskState::kRunning);
  EXPECT_NE(st[1].state, TaskState::kRunning);
  const std::string uid = std::to_string(::getuid());
  EXPECT_NE(logged("squeue").find("-u " + uid + " "), std::string::npos) << logged("squeue");
  EXPECT_EQ(cancel(p), 1);
  EXPECT_EQ(logged("scancel"), "--user=" + uid + " --name=" + own + " 300\n");
  // Submitting over the shot's own queued job is refused; the other job does not count.
  try {
    submit(p, {});
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("(300)"), std::string::npos) << e.what();
  }
}

// What a TD's script reads: submit's job ids, status as JSON and as an exit code, the settings
// submit recorded.
TEST_F(SlurmTest, SubmitRecordsItsArraysAndStatusReadsAsJsonAndAnExitCode) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out").string());
  const Submitted s = submit(p, {});
  ASSERT_EQ(int(s.arrays.size()), s.jobs);
  EXPECT_EQ(s.arrays[0].job, "100");
  EXPECT_EQ(s.arrays[0].name, "emaki:" + p.shots[0].name + ":prepare");
  EXPECT_EQ(s.arrays[0].tasks, 1);
  EXPECT_EQ(submitted_chunk(p), p.chunk);
  EXPECT_EQ(submitted_threads(p), p.threads);
  // Nothing ran (the stand-in only queued them) and the queue is empty: not run.
  std::vector<TaskStatus> st = status(p);
  EXPECT_EQ(status_exit_code(st), 4);
  const std::string json = status_json(p, st);
  EXPECT_EQ(json.front(), '[');
  EXPECT_NE(json.find("\"state\": \"not run\", \"job\": \"100_0\", \"exit\": null"),
            std::string::npos)
      << json;
  for (TaskStatus& t : st) t.state = TaskState::kDone;
  EXPECT_EQ(status_exit_code(st), 0);
  st[1].state = TaskState::kPending;
  EXPECT_EQ(status_exit_code(st), 3);
  st[0].state = TaskState::kNotSubmitted;
  EXPECT_EQ(status_exit_code(st), 3);
  st[1].state = TaskState::kDone;
  EXPECT_EQ(status_exit_code(st), 5);
  st[1].state = TaskState::kFailed;
  EXPECT_EQ(status_exit_code(st), 4);
}

TEST(SlurmFailure, SaysWhatIsMissingInOneLine) {
  EXPECT_NE(slurm_failure("squeue", -1, "").find("not installed"), std::string::npos);
  const std::string no_conf = slurm_failure(
      "squeue", 1,
      "squeue: error: resolve_ctls_from_dns_srv: res_nsearch error: Unknown host\nsqueue: "
      "error: fetch_config: DNS SRV lookup failed\nsqueue: fatal: Could not establish a "
      "configuration source\n");
  EXPECT_NE(no_conf.find("not configured"), std::string::npos) << no_conf;
  EXPECT_EQ(no_conf.find('\n'), std::string::npos);
  const std::string down = slurm_failure(
      "squeue", 1, "slurm_load_jobs error: Unable to contact slurm controller (connect failure)\n");
  EXPECT_NE(down.find("controller does not answer"), std::string::npos) << down;
  EXPECT_EQ(down.find('\n'), std::string::npos);
  EXPECT_EQ(slurm_failure("sbatch", 1, "sbatch: error: Invalid partition\nmore\n"),
            "sbatch failed (1): sbatch: error: Invalid partition");
}

// The records of an array must be on disk before the next array is queued: a write that fails
// (here past RLIMIT_FSIZE, as on a full disk) cancels that array and stops the submission.
TEST_F(SlurmTest, AJobsRecordThatCannotBeWrittenStopsTheSubmission) {
  const shot::Plan p = plan_of("a.toml", (dir_ / "out").string());
  const std::string farm = p.shots[0].shot.outputs.folder + "/farm";
  fs::create_directories(farm);
  std::string old;
  for (int i = 0; i < 400; ++i) old += job_record("old.task." + std::to_string(i), "7", 0);
  write_file(farm + "/jobs.tsv", old);
  ::signal(SIGXFSZ, SIG_IGN);
  rlimit saved{};
  ::getrlimit(RLIMIT_FSIZE, &saved);
  rlimit small = saved;
  small.rlim_cur = old.size() + 8;
  ::setrlimit(RLIMIT_FSIZE, &small);
  std::string error;
  try {
    submit(p, {});
  } catch (const Error& e) {
    error = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &saved);
  ::signal(SIGXFSZ, SIG_DFL);
  EXPECT_NE(error.find(farm + "/jobs.tsv: cannot record job 100"), std::string::npos) << error;
  EXPECT_NE(error.find("cancelled"), std::string::npos) << error;
  EXPECT_EQ(logged("sbatch").find('\n'), logged("sbatch").size() - 1) << "a second array queued";
  EXPECT_NE(logged("scancel").find(" 100\n"), std::string::npos);
}

}  // namespace
}  // namespace emaki::farm
