#include "farm/process.h"

#include <gtest/gtest.h>

#include <string>

namespace emaki::farm {
namespace {

TEST(Process, CapturesBothOutputsAndTheExitCode) {
  const ProcessResult r = run_process({"sh", "-c", "echo out; echo err >&2; exit 3"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(r.out, "out\n");
  EXPECT_EQ(r.err, "err\n");
}

// Both pipes are drained at once: a child filling stderr far past a pipe's buffer before
// writing stdout does not block.
TEST(Process, ALargeOutputOnBothPipesDoesNotBlock) {
  const ProcessResult r =
      run_process({"sh", "-c", "head -c 300000 /dev/zero >&2; head -c 200000 /dev/zero"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.size(), 200000u);
  EXPECT_EQ(r.err.size(), 300000u);
}

TEST(Process, StdinIsEmpty) {
  const ProcessResult r = run_process({"cat"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, "");
}

TEST(Process, AMissingProgramIsReportedNotRun) {
  const ProcessResult r = run_process({"emaki-no-such-program"});
  EXPECT_EQ(r.exit_code, -1);
  EXPECT_NE(r.err.find("cannot run 'emaki-no-such-program'"), std::string::npos) << r.err;
}

TEST(Process, KilledBySignalIsMinusOne) {
  const ProcessResult r = run_process({"sh", "-c", "kill -9 $$"});
  EXPECT_EQ(r.exit_code, -1);
}

}  // namespace
}  // namespace emaki::farm
