#include "store/output_store.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>

#include "core/error.h"
#include "core/version.h"
#include "store/settings_manifests.h"
#include "tests/test_dir.h"

namespace emaki::io {
namespace {

namespace fs = std::filesystem;

class OutputStore : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_dir("emaki_store"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(OutputStore, ASecondLockOnTheFolderNamesTheHolder) {
  auto first = std::make_unique<FolderLock>(dir_.string());
  try {
    FolderLock second(dir_.string());
    FAIL() << "the folder was locked twice";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(".emaki.lock"), std::string::npos) << what;
    EXPECT_NE(what.find("pid " + std::to_string(::getpid())), std::string::npos) << what;
  }
  first.reset();
  EXPECT_NO_THROW(FolderLock again(dir_.string()));
}

TEST_F(OutputStore, ManifestsRoundTripAndNameTheFirstChange) {
  const std::string path = (dir_ / ".emaki-manifest").string();
  EXPECT_FALSE(read_manifest(path));
  const Manifest m = {"outputs_format = 1", "size = 32x24", "layers.base.single_colour = true"};
  write_manifest(path, m);
  const auto back = read_manifest(path);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, m);
  EXPECT_EQ(manifest_difference(m, m), "");
  Manifest changed = m;
  changed[1] = "size = 40x30";
  EXPECT_EQ(manifest_difference(m, changed), "size was 32x24, now 40x30");
  changed.push_back("layers.base.channel = 0");
  EXPECT_EQ(manifest_difference(m, {m[0], m[1], m[2], changed[3]}), "layers.base.channel is new");
}

TEST_F(OutputStore, ManifestsNameTheVersionButCompareWithoutIt) {
  const Manifest m = frames_manifest(pipeline::Shot{});
  const std::string line = std::string(kVersionKey) + " = " + version();
  EXPECT_NE(std::find(m.begin(), m.end(), line), m.end());
  Manifest older, without;
  for (const std::string& l : m) {
    older.push_back(l == line ? std::string(kVersionKey) + " = 0.0.1" : l);
    if (l != line) without.push_back(l);
  }
  EXPECT_TRUE(manifest_current(older, m));
  EXPECT_TRUE(manifest_current(without, m));
}

TEST_F(OutputStore, FileDigestFollowsContent) {
  std::ofstream(dir_ / "a") << "hello";
  std::ofstream(dir_ / "b") << "hellp";
  EXPECT_EQ(file_digest((dir_ / "a").string()), file_digest((dir_ / "a").string()));
  EXPECT_NE(file_digest((dir_ / "a").string()), file_digest((dir_ / "b").string()));
  EXPECT_EQ(file_digest((dir_ / "none").string()), "missing");
}

// The digest is remembered per file identity: a file rewritten (another modification time)
// gets its new digest, and an input read whole has its digest without a second read.
TEST_F(OutputStore, FileDigestIsRememberedUntilTheFileChanges) {
  const std::string a = (dir_ / "a").string();
  std::ofstream(a) << "hello";
  const std::string first = file_digest(a);
  std::ofstream(a) << "hellp";
  fs::last_write_time(a, fs::last_write_time(a) + std::chrono::seconds(2));
  EXPECT_NE(file_digest(a), first);
  const std::string b = (dir_ / "b").string();
  std::ofstream(b) << "hello";
  const std::optional<std::string> bytes = read_input_file(b, 100);
  ASSERT_TRUE(bytes.has_value());
  EXPECT_EQ(*bytes, "hello");
  EXPECT_EQ(file_digest(b), first);
  EXPECT_FALSE(read_input_file(b, 4).has_value());                // over its cap
  EXPECT_FALSE(read_input_file(dir_.string(), 100).has_value());  // a folder
}

}  // namespace
}  // namespace emaki::io
