// The memory check made before a shot's work (shot/memory.h): a limit of the caller's, named by
// its field, and what the machine has, named by the shot.
#include "shot/memory.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>

#include "core/error.h"
#include "shot/api.h"
#include "tests/error_of.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

using test::error_of;

TEST(Memory, TheCallersLimitIsNamedByItsField) {
  const Error e =
      error_of([] { check_memory(int64_t(3) << 30, int64_t(1) << 30, "s", "the run"); });
  EXPECT_EQ(e.field(), "max_memory");
  EXPECT_EQ(e.message(),
            "the run needs about 3.0 GB of memory at its peak, more than the 1.0 GB allowed");
  EXPECT_NO_THROW(check_memory(int64_t(1) << 20, int64_t(1) << 30, "s", "the run"));
  EXPECT_NO_THROW(check_memory(int64_t(1) << 20, 0, "s", "the run"));
}

TEST(Memory, MoreThanTheMachineHasIsNamedByTheSubject) {
  const int64_t available = available_memory_bytes();
  ASSERT_GT(available, 0);
  const Error e = error_of([&] { check_memory(available * 2, 0, "shot.toml", "the run"); });
  EXPECT_EQ(e.subject(), "shot.toml");
  EXPECT_EQ(e.field(), "");
  EXPECT_NE(e.message().find("this machine has available"), std::string::npos) << e.what();
  EXPECT_EQ(memory_text(int64_t(512) << 20), "512 MB");
  EXPECT_EQ(memory_text(int64_t(81) << 30), "81.0 GB");
}

// A 16384x16384 shot (within the pixel budget) fails before any work, not with std::bad_alloc.
TEST(Memory, AShotTooLargeForTheMachineFailsBeforeItsWork) {
  if (available_memory_bytes() > (int64_t(200) << 30)) GTEST_SKIP() << "a machine of 200 GB";
  const fs::path out = fs::temp_directory_path() / "emaki_memory_test_out";
  fs::remove_all(out);
  const std::string text = "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\n" +
                           "frames = [0, 1]\nsize = [16384, 16384]\n[exemplars.sphere]\n" +
                           "painting = \"" + kData + "/stylit/source_style.png\"\n" +
                           "[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n" +
                           "[outputs]\nfolder = \"" + out.string() + "\"\n";
  const pipeline::Shot shot = open_text(text, "/tmp/big.toml");
  const Error e = error_of([&] { run(shot, Request{}); });
  EXPECT_EQ(e.subject(), "/tmp/big.toml");
  EXPECT_NE(e.message().find("the run of 16384x16384 frames needs about"), std::string::npos)
      << e.what();
  Request limited;
  limited.max_memory_mb = 100;
  EXPECT_EQ(error_of([&] { composite(shot, limited); }).field(), "max_memory");
  EXPECT_EQ(error_of([&] { prepare(shot, limited); }).field(), "max_memory");
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace emaki::shot
