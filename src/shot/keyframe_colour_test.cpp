// A painted key frame's pass file is a studio render like the shot's frames: its albedo is read
// from source.passes_colorspace into the config's scene_linear; its data passes are not touched.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "io/image_io.h"
#include "render/passes.h"
#include "shot/api.h"
#include "shot/inputs.h"
#include "tests/small_painting.h"
#include "tests/test_dir.h"

namespace emaki::shot {
namespace {

namespace fs = std::filesystem;
const std::string kData = EMAKI_TEST_DATA;

TEST(KeyframeColour, AlbedoIsReadFromThePassesColourSpace) {
  const test::TempDir scratch("keyframe_colour");
  const fs::path& dir = scratch.path();
  const int w = 16, h = 12;
  Image<float> p(w, h, render::kChannelCount);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) p(x, y, render::kAlbedo + c) = 0.05f + 0.03f * x + 0.2f * c;
      p(x, y, render::kNormal + 2) = 0.1f * y;
    }
  io::WriteOptions exr;
  exr.format = io::SampleFormat::kFloat;
  exr.channel_names = render::channel_names();
  io::write_image((dir / "frame_0000.exr").string(), p.cview(), exr);
  io::write_image((dir / "key.exr").string(), p.cview(), exr);
  test::write_small_painting(kData + "/stylit/source_style.png", (dir / "key.png").string(), w, h);
  const auto shot = [&](const std::string& space) {
    return open_text("[source]\nsequence = \"frame_%04d.exr\"\nframes = [0, 0]\n" +
                         (space.empty() ? "" : "passes_colorspace = \"" + space + "\"\n") +
                         "[exemplars.key]\nkind = \"keyframe\"\npainting = \"key.png\"\n"
                         "passes = \"key.exr\"\n[layers.base]\nkind = \"base\"\n"
                         "exemplar = \"key\"\nguides = { albedo = 1.0, normal = 1.0 }\n"
                         "[outputs]\nfolder = \"out\"\n",
                     (dir / "shot.toml").string());
  };
  const pipeline::Shot linear = shot(""), acescg = shot("ACEScg");
  const Image<float> a = std::move(load_exemplars(linear).at("key").passes);
  const Image<float> b = std::move(load_exemplars(acescg).at("key").passes);
  Image<float> want = p.clone();
  ImageView<float> albedo = want.view();
  albedo.data += render::kAlbedo;
  albedo.channels = want.channels();
  acescg.colour.get().convert(albedo, "ACEScg", "scene_linear");
  float moved = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int k = render::kAlbedo + c;
        EXPECT_EQ(a(x, y, k), p(x, y, k)) << "scene_linear is read as it is";
        EXPECT_NEAR(b(x, y, k), want(x, y, k), 1e-6f);
        moved = std::max(moved, std::abs(b(x, y, k) - p(x, y, k)));
      }
      EXPECT_EQ(b(x, y, render::kNormal + 2), p(x, y, render::kNormal + 2));  // data: as it is
    }
  EXPECT_GT(moved, 0.01f);  // ACEScg is not scene-linear Rec.709
}

}  // namespace
}  // namespace emaki::shot
