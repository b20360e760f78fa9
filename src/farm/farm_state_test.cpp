// Reading a farm folder back: FIFOs, devices and oversized files are refused without blocking or
// reading them whole; records that are not what emaki writes are errors naming the line.
#include "farm/farm_state.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"

namespace emaki::farm {
namespace {

namespace fs = std::filesystem;

class FarmState : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_farm_state_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
  }
  fs::path dir_;
};

TEST_F(FarmState, MissingFilesAreNothing) {
  EXPECT_FALSE(read_state_file(path("jobs.tsv"), kMaxJobsFileBytes));
  EXPECT_FALSE(read_file_tail(path("x.log"), 10));
}

// A FIFO would block a plain open until someone writes; status must not hang on it.
TEST_F(FarmState, AFifoIsRefusedWithoutBlocking) {
  ASSERT_EQ(::mkfifo(path("chunk").c_str(), 0600), 0);
  EXPECT_THROW(read_state_file(path("chunk"), kMaxSmallFileBytes), Error);
  EXPECT_THROW(read_file_tail(path("chunk"), kLogTailBytes), Error);
}

TEST_F(FarmState, DevicesAndFoldersAreRefused) {
  fs::create_symlink("/dev/zero", path("jobs.tsv"));
  try {
    read_state_file(path("jobs.tsv"), kMaxJobsFileBytes);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), path("jobs.tsv"));
    EXPECT_NE(e.message().find("not a regular file"), std::string::npos);
  }
  fs::create_symlink("/dev/zero", path("task.log"));
  EXPECT_THROW(read_file_tail(path("task.log"), kLogTailBytes), Error);
  fs::create_directories(path("status.exit"));
  EXPECT_THROW(read_state_file(path("status.exit"), kMaxSmallFileBytes), Error);
}

TEST_F(FarmState, FilesPastTheCapAreRefusedAndLogsReadOnlyTheirTail) {
  write("chunk", std::string(5000, '7'));
  EXPECT_THROW(read_state_file(path("chunk"), kMaxSmallFileBytes), Error);
  write("ok", "8\n");
  EXPECT_EQ(read_state_file(path("ok"), kMaxSmallFileBytes), "8\n");
  write("task.log", std::string(100000, 'x') + "\nemaki: error: the end\n");
  const std::optional<std::string> tail = read_file_tail(path("task.log"), 30);
  ASSERT_TRUE(tail);
  EXPECT_EQ(*tail, std::string(7, 'x') + "\nemaki: error: the end\n");
}

TEST_F(FarmState, JobsRecordsParseAndALaterLineWins) {
  const std::string text = job_record("a.prepare", "12", 0) + job_record("a.passes.0-7", "13", 0) +
                           job_record("a.prepare", "20", 0) + "\n";
  const auto jobs = parse_jobs(text, "jobs.tsv");
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs.at("a.prepare"), "20_0");
  EXPECT_EQ(jobs.at("a.passes.0-7"), "13_0");
}

TEST_F(FarmState, JobsRecordsThatAreNotEmakisAreErrorsNamingTheLine) {
  for (const std::string bad :
       {"a.prepare\t12\n", "a.prepare\t-1\t0\n", "a.prepare\t12\t0 x\n", "\t12\t0\n",
        "a\x01\t12\t0\n", "a\t1;id\t0\n", "a\t1234567890123456789\t0\n"}) {
    try {
      parse_jobs(job_record("ok", "1", 0) + bad, "jobs.tsv");
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.subject(), "jobs.tsv");
      EXPECT_NE(e.message().find("line 2"), std::string::npos) << e.message();
    }
  }
}

TEST_F(FarmState, ChunksAndExitCodes) {
  EXPECT_EQ(parse_chunk("8\n", "chunk"), 8);
  for (const std::string bad : {"", "0", "x", "8 ", "-3", "99999999999"})
    EXPECT_THROW(parse_chunk(bad, "chunk"), Error) << bad;
  EXPECT_EQ(parse_threads("4\n", "threads"), 4);
  for (const std::string bad : {"", "0", "x", "4 ", "-3", "1025"})
    EXPECT_THROW(parse_threads(bad, "threads"), Error) << bad;
  EXPECT_EQ(parse_exit_code("0\n"), 0);
  EXPECT_EQ(parse_exit_code("137\n"), 137);
  EXPECT_FALSE(parse_exit_code(""));
  EXPECT_FALSE(parse_exit_code("256\n"));
  EXPECT_FALSE(parse_exit_code("-1\n"));
  EXPECT_FALSE(parse_exit_code("1 2\n"));
}

TEST_F(FarmState, QueueLinesCarryTheJobNameLast) {
  const auto q = parse_queue(
      "12_3|RUNNING|None|emaki:a:layer\n13|PENDING|Dependency|my|odd|name\ngarbage\n"
      "x_1|RUNNING|None|n\n");
  ASSERT_EQ(q.size(), 2u);
  EXPECT_EQ(q.at("12_3").state, "RUNNING");
  EXPECT_EQ(q.at("12_3").name, "emaki:a:layer");
  EXPECT_EQ(q.at("13_0").reason, "Dependency");
  EXPECT_EQ(q.at("13_0").name, "my|odd|name");
}

}  // namespace
}  // namespace emaki::farm
