// confined_file(): what a request path may reach under a served folder.
#include "view/confine.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace emaki::view {
namespace {

namespace fs = std::filesystem;

class Confine : public ::testing::Test {
 protected:
  void SetUp() override {
    base = fs::temp_directory_path() / ("emaki_confine_" + std::to_string(::getpid()));
    fs::remove_all(base);
    root = base / "out";
    fs::create_directories(root / "composite");
    std::ofstream(root / "composite" / "frame_0000.png") << "png";
    std::ofstream(root / "composite" / ".emaki-manifest") << "manifest";
    std::ofstream(base / "secret.txt") << "secret";
    fs::create_symlink(base / "secret.txt", root / "composite" / "link_out.png");
    fs::create_symlink(root / "composite" / "frame_0000.png", root / "composite" / "link_in.png");
    fs::create_directory_symlink(base, root / "up");
  }
  void TearDown() override { fs::remove_all(base); }
  fs::path base, root;
};

TEST_F(Confine, AFileInsideIsServed) {
  const auto f = confined_file(root, "composite/frame_0000.png");
  ASSERT_TRUE(f);
  EXPECT_EQ(*f, fs::canonical(root / "composite" / "frame_0000.png"));
}

TEST_F(Confine, DotDotIsRefusedEvenWhenItWouldStayInside) {
  EXPECT_FALSE(confined_file(root, "../secret.txt"));
  EXPECT_FALSE(confined_file(root, "composite/../composite/frame_0000.png"));
  EXPECT_FALSE(confined_file(root, "composite/.."));
}

TEST_F(Confine, PercentIsALiteralCharacterNotDecodedAgain) {
  EXPECT_FALSE(confined_file(root, "%2e%2e/secret.txt"));
  EXPECT_FALSE(confined_file(root, "composite/%2e%2e/%2e%2e/secret.txt"));
}

TEST_F(Confine, AbsolutePathsAreRefused) {
  EXPECT_FALSE(confined_file(root, (base / "secret.txt").string()));
  EXPECT_FALSE(confined_file(root, "/etc/passwd"));
  EXPECT_FALSE(confined_file(root, (root / "composite/frame_0000.png").string()));
}

TEST_F(Confine, SymlinksOutAreRefusedAndSymlinksInsideFollowed) {
  EXPECT_FALSE(confined_file(root, "composite/link_out.png"));
  EXPECT_FALSE(confined_file(root, "up/secret.txt"));
  EXPECT_TRUE(confined_file(root, "composite/link_in.png"));
}

TEST_F(Confine, HiddenFilesFoldersAndTheRootItselfAreRefused) {
  EXPECT_FALSE(confined_file(root, "composite/.emaki-manifest"));
  EXPECT_FALSE(confined_file(root, "composite"));
  EXPECT_FALSE(confined_file(root, "."));
  EXPECT_FALSE(confined_file(root, ""));
}

TEST_F(Confine, ControlCharactersBackslashesEmptyPartsAndBadUtf8AreRefused) {
  EXPECT_FALSE(confined_file(root, std::string("composite/frame_0000.png\0x", 26)));
  EXPECT_FALSE(confined_file(root, "composite\\frame_0000.png"));
  EXPECT_FALSE(confined_file(root, "composite//frame_0000.png"));
  EXPECT_FALSE(confined_file(root, "composite/frame_0000.png/"));
  EXPECT_FALSE(confined_file(root, "composite/\xff.png"));
  EXPECT_FALSE(confined_file(root, "composite/\nframe_0000.png"));
}

TEST_F(Confine, LongPathsAreRefusedBeforeTheFileSystem) {
  std::string name = "composite/";
  while (name.size() <= kMaxRequestPath) name += "a/";
  EXPECT_FALSE(confined_file(root, name + "frame_0000.png"));
}

TEST_F(Confine, MissingFilesAndAMissingRootAreRefused) {
  EXPECT_FALSE(confined_file(root, "composite/frame_0001.png"));
  EXPECT_FALSE(confined_file(base / "nothing", "composite/frame_0000.png"));
}

TEST(LiesWithin, ComparesWholeComponents) {
  EXPECT_TRUE(lies_within("/a/b/c", "/a/b"));
  EXPECT_TRUE(lies_within("/a/b", "/a/b"));
  EXPECT_TRUE(lies_within("/a/b/c", "/a/b/"));
  EXPECT_FALSE(lies_within("/a/bc", "/a/b"));
  EXPECT_FALSE(lies_within("/a", "/a/b"));
}

}  // namespace
}  // namespace emaki::view
