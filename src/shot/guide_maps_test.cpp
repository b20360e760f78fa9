// The shot file's per-pixel guide weights (layers.NAME.guides.PASS = { weight, map }) and
// layers.NAME.temporal_confidence.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/error.h"
#include "io/image_io.h"
#include "shot/inputs.h"
#include "shot/parser.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

std::string shot_text(const std::string& layer_lines) {
  return "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nframes = [0, 3]\nsize = [64, 48]\n" +
         "[exemplars.sphere]\npainting = \"" + kData + "/stylit/source_style.png\"\n" +
         "[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n" + layer_lines +
         "\n[outputs]\nfolder = \"/tmp/emaki_guide_maps_test_out\"\n";
}

std::string error_of(const std::string& layer_lines, const std::string& path = "/tmp/shot.toml") {
  try {
    parse_shot(shot_text(layer_lines), path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

class GuideMaps : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("emaki_guide_maps_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string shot_path() const { return (dir_ / "shot.toml").string(); }
  void write_map(const std::string& name, int w, int h) const {
    Image<float> m(w, h, 1);
    m.fill(0.5f);
    io::write_image((dir_ / name).string(), m.cview());
  }
  fs::path dir_;
};

TEST_F(GuideMaps, TableFormGivesWeightAndMap) {
  write_map("paint.png", 64, 48);
  const pipeline::Shot s =
      parse_shot(shot_text("guides = { normal = 1.0, diffuse = { weight = 1.5, map = \"shadow\" }, "
                           "albedo = { map = \"paint.png\" } }"),
                 shot_path());
  const auto& g = s.layers[0].guides;
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g[0].map_pass, "");
  EXPECT_EQ(g[0].map_image, "");
  EXPECT_FLOAT_EQ(g[1].weight, 1.5f);
  EXPECT_EQ(g[1].map_pass, "shadow");
  EXPECT_FLOAT_EQ(g[2].weight, 1.0f);
  EXPECT_EQ(g[2].map_image, (dir_ / "paint.png").string());  // relative to the shot file
  const pipeline::WeightMapImages maps = load_weight_maps(s);
  ASSERT_EQ(maps.size(), 1u);
  EXPECT_EQ(maps.at(g[2].map_image).channels(), 1);
}

TEST_F(GuideMaps, ErrorsNameTheKey) {
  struct Case {
    std::string lines, starts;
  } cases[] = {
      {"guides = { normal = { map = \"normal\" } }",
       "layers.base.guides.normal.map: the 'normal' pass does not hold weights in [0, 1]"},
      {"guides = { normal = { map = \"nope.png\" } }",
       "layers.base.guides.normal.map: no such file"},
      {"guides = { normal = { wieght = 2 } }",
       "layers.base.guides.normal.wieght: unknown key — did you mean 'weight'?"},
      {"guides = { normal = { weight = 2000 } }",
       "layers.base.guides.normal.weight: must be in [0, 1000]"},
      {"guides = { normal = { map = 3 } }", "layers.base.guides.normal.map: expected a string"},
      {"temporal_confidence = 1", "layers.base.temporal_confidence: expected true or false"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.lines, shot_path());
    EXPECT_EQ(e.rfind(c.starts, 0), 0u) << c.starts << " vs " << e;
  }
}

TEST_F(GuideMaps, PaintedMapMustHaveTheShotsSize) {
  write_map("small.png", 32, 48);
  const pipeline::Shot s =
      parse_shot(shot_text("guides = { normal = { map = \"small.png\" } }"), shot_path());
  try {
    load_weight_maps(s);
    FAIL() << "a 32x48 map accepted for a 64x48 shot";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("layers.base.guides.normal.map: ", 0), 0u) << e.what();
  }
}

TEST_F(GuideMaps, TemporalConfidenceIsOnUnlessTurnedOff) {
  EXPECT_TRUE(parse_shot(shot_text(""), shot_path()).layers[0].temporal.confidence);
  EXPECT_EQ(parse_shot(shot_text(""), shot_path()).layers[0].temporal.uniformity, 1000.0f);
  EXPECT_EQ(parse_shot(shot_text("temporal_uniformity = 3500"), shot_path())
                .layers[0]
                .temporal.uniformity,
            3500.0f);
  EXPECT_FALSE(parse_shot(shot_text("temporal_confidence = false"), shot_path())
                   .layers[0]
                   .temporal.confidence);
}

}  // namespace
}  // namespace emaki::shot
