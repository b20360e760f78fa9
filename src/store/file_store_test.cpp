#include "store/file_store.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "core/error.h"

namespace emaki::io {
namespace {

namespace fs = std::filesystem;

const std::string kData = EMAKI_TEST_DATA;

class FileStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_file_store_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    shot_.path = (dir_ / "shot.toml").string();
    shot_.source.scene_path = kData + "/scenes/Fox.glb";
    shot_.source.width = shot_.source.render.width = 8;
    shot_.source.height = shot_.source.render.height = 6;
    shot_.source.last_frame = 3;
    pipeline::Exemplar e;
    e.name = "sphere";
    e.painting = kData + "/stylit/source_style.png";
    shot_.exemplars.push_back(e);
    pipeline::Layer l;
    l.name = "base";
    l.exemplar = "sphere";
    l.guides.push_back({"normal"});
    shot_.layers.push_back(l);
    shot_.outputs.folder = (dir_ / "out").string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A layer frame as the pipeline makes it: the touch and the mask's coverage.
  static Image<float> layer_frame(float touch) {
    Image<float> v(8, 6, 2);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) v(x, y, 0) = touch + 0.01f * float(x + y), v(x, y, 1) = 1.0f;
    return v;
  }

  fs::path dir_;
  pipeline::Shot shot_;
};

TEST_F(FileStoreTest, PathsFollowTheDocumentedLayout) {
  const FileStore store(shot_);
  const OutputPaths& p = store.paths();
  const std::string out = shot_.outputs.folder;
  EXPECT_EQ(p.layer_exr("base", 7), out + "/layers/base/base_0007.exr");
  EXPECT_EQ(p.layer_png("base", 7), out + "/layers/base/base_0007.png");
  EXPECT_EQ(p.layer_field("base", 7), out + "/layers/base/.base_0007.nnf");
  EXPECT_EQ(p.composite_png(12), out + "/composite/frame_0012.png");
  EXPECT_EQ(p.composite_exr(12), out + "/composite/frame_0012.exr");
  EXPECT_EQ(p.layered_exr(12), out + "/layered/frame_0012.exr");
  EXPECT_EQ(p.mp4(), out + "/preview.mp4");
  EXPECT_EQ(p.contact_sheet(), out + "/contact_sheet.png");
  EXPECT_EQ(p.passes_file(3), out + "/passes/frame_0003.passes");
}

// A layer frame is read back bit for bit: resuming continues from exactly what was written.
TEST_F(FileStoreTest, ALayerFrameReadsBackBitForBit) {
  FileStore store(shot_);
  const pipeline::Layer& layer = shot_.layers[0];
  EXPECT_FALSE(store.has_layer(layer, 2));
  const Image<float> v = layer_frame(0.3f);
  store.write_layer(layer, 2, v.cview());
  ASSERT_TRUE(store.has_layer(layer, 2));
  EXPECT_FALSE(store.has_layer(layer, 1));
  const Image<float> back = store.read_layer(layer, 2);
  ASSERT_EQ(back.width(), 8);
  ASSERT_EQ(back.height(), 6);
  ASSERT_EQ(back.channels(), 2);
  for (int y = 0; y < 6; ++y)
    EXPECT_EQ(std::memcmp(back.row(y), v.row(y), 8 * 2 * sizeof(float)), 0) << "row " << y;
}

// Frames made under other settings are redone by a run and refused by a reader of finished
// work, which names what changed.
TEST_F(FileStoreTest, FramesOfOtherSettingsAreDroppedOrRefused) {
  {
    FileStore store(shot_);
    store.write_layer(shot_.layers[0], 0, layer_frame(0.5f).cview());
  }
  shot_.layers[0].synth.seed = 7;
  try {
    const FileStore reader(shot_, StoreMode::kReadFinished);
    (void)reader.has_layer(shot_.layers[0], 0);
    const Image<float> v = reader.read_layer(shot_.layers[0], 0);
    FAIL() << "a frame made with another seed was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("layers.base.synth was"), std::string::npos) << e.what();
  }
  FileStore run(shot_);
  EXPECT_FALSE(run.has_layer(shot_.layers[0], 0));
}

TEST_F(FileStoreTest, ASecondStoreOnTheFolderNamesTheHolder) {
  const FileStore first(shot_);
  try {
    const FileStore second(shot_);
    FAIL() << "two stores held the folder";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pid " + std::to_string(::getpid())), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace emaki::io
