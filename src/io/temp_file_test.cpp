#include "io/temp_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "tests/test_dir.h"

namespace emaki::io {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

class TempFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::fresh_test_dir("emaki_temp"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST(TemporaryName, RecognisesOnlyEmakisPattern) {
  std::string target;
  EXPECT_TRUE(is_temporary_name(".frame_0001.emaki-tmp-0123456789abcdef.png", &target));
  EXPECT_EQ(target, "frame_0001.png");
  EXPECT_TRUE(is_temporary_name("..emaki-manifest.emaki-tmp-0123456789abcdef", &target));
  EXPECT_EQ(target, ".emaki-manifest");
  EXPECT_FALSE(is_temporary_name(".vimrc.tmp"));
  EXPECT_FALSE(is_temporary_name(".x.tmp123.png"));
  EXPECT_FALSE(is_temporary_name(".frame_0001.tmp4242.png"));
  EXPECT_FALSE(is_temporary_name("frame.emaki-tmp-0123456789abcdef.png"));  // not hidden
  EXPECT_FALSE(is_temporary_name(".frame.emaki-tmp-0123456789ABCDEF.png"));
  EXPECT_FALSE(is_temporary_name(".frame.emaki-tmp-0123.png"));
  EXPECT_FALSE(is_temporary_name(".frame.emaki-tmp-0123456789abcdefx"));
}

TEST_F(TempFiles, TemporariesAreUnpredictableAndRemovedUnlessCommitted) {
  const std::string target = (dir_ / "a.png").string();
  std::string first, second;
  {
    TempFile a(target, "a.png"), b(target, "a.png");
    first = a.path();
    second = b.path();
    EXPECT_NE(first, second);
    std::string t;
    EXPECT_TRUE(is_temporary_name(fs::path(first).filename().string(), &t));
    EXPECT_EQ(t, "a.png");
    EXPECT_TRUE(fs::is_regular_file(first));
  }
  EXPECT_FALSE(fs::exists(first));
  EXPECT_FALSE(fs::exists(second));
  EXPECT_FALSE(fs::exists(target));
}

TEST_F(TempFiles, CommitReplacesASymlinkAtTheTargetWithoutFollowingIt) {
  std::ofstream(dir_ / "victim") << "precious";
  fs::create_symlink(dir_ / "victim", dir_ / "a.txt");
  TempFile t((dir_ / "a.txt").string(), "a.txt");
  ASSERT_EQ(::write(t.fd(), "new", 3), 3);
  t.commit();
  EXPECT_FALSE(fs::is_symlink(dir_ / "a.txt"));
  EXPECT_EQ(slurp(dir_ / "a.txt"), "new");
  EXPECT_EQ(slurp(dir_ / "victim"), "precious");
}

TEST_F(TempFiles, ATemporarySwappedForASymlinkIsNotCommittedNorRemoved) {
  std::ofstream(dir_ / "victim") << "precious";
  std::string path;
  {
    TempFile t((dir_ / "a.txt").string(), "a.txt");
    path = t.path();
    fs::remove(path);
    fs::create_symlink(dir_ / "victim", path);
    EXPECT_THROW(t.commit(), Error);
  }
  EXPECT_FALSE(fs::exists(dir_ / "a.txt"));
  EXPECT_TRUE(fs::is_symlink(path));  // not ours: left for the user to see
  EXPECT_EQ(slurp(dir_ / "victim"), "precious");
}

TEST_F(TempFiles, CleanUpRemovesOnlyOurOwnRegularTemporaries) {
  auto touch = [&](const std::string& n) { std::ofstream(dir_ / n) << n; };
  touch(".vimrc.tmp");
  touch(".x.tmp123.png");
  touch(".frame_0001.emaki-tmp-0123456789abcdef.png");  // ours: removed
  touch(".notes.emaki-tmp-0123456789abcdef.txt");       // pattern, but not an emaki output
  touch("target");
  fs::create_symlink(dir_ / "target", dir_ / ".frame_0002.emaki-tmp-0123456789abcdef.png");
  fs::create_directory(dir_ / ".frame_0003.emaki-tmp-0123456789abcdef.png");
  remove_temporaries(dir_.string(), [](const std::string& t) { return t.rfind("frame_", 0) == 0; });
  EXPECT_TRUE(fs::exists(dir_ / ".vimrc.tmp"));
  EXPECT_TRUE(fs::exists(dir_ / ".x.tmp123.png"));
  EXPECT_FALSE(fs::exists(dir_ / ".frame_0001.emaki-tmp-0123456789abcdef.png"));
  EXPECT_TRUE(fs::exists(dir_ / ".notes.emaki-tmp-0123456789abcdef.txt"));
  EXPECT_TRUE(fs::is_symlink(dir_ / ".frame_0002.emaki-tmp-0123456789abcdef.png"));
  EXPECT_TRUE(fs::is_directory(dir_ / ".frame_0003.emaki-tmp-0123456789abcdef.png"));
  EXPECT_EQ(slurp(dir_ / "target"), "target");
}

}  // namespace
}  // namespace emaki::io
