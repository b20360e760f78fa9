#include "shot/parser.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "core/error.h"
#include "shot/toml_reader.h"

namespace emaki::shot {
namespace {

const std::string kData = EMAKI_TEST_DATA;

std::string minimal(const std::string& layers) {
  return "[source]\nscene = \"" + kData + "/scenes/Fox.glb\"\nframes = [0, 3]\nsize = [64, 48]\n" +
         "[exemplars.sphere]\npainting = \"" + kData + "/stylit/source_style.png\"\n" + layers +
         "[outputs]\nfolder = \"/tmp/emaki_shot_file_test_out\"\n";
}

std::string error_of(const std::string& text) {
  try {
    parse_shot(text, "/tmp/shot.toml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ShotFile, EditDistance) {
  EXPECT_EQ(edit_distance("weight", "wieght"), 2);
  EXPECT_EQ(edit_distance("", "abc"), 3);
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
  EXPECT_EQ(closest_key("wieght", {"weight", "width"}), "weight");
  EXPECT_EQ(closest_key("banana", {"weight", "width"}), "");
}

TEST(ShotFile, LightTurnIsReadAndRanged) {
  const std::string layer = "[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n";
  auto with_light = [&](const std::string& light) {
    std::string text = minimal(layer);
    text.insert(text.find("[exemplars."), "[source.light]\n" + light + "\n");
    return text;
  };
  EXPECT_FLOAT_EQ(parse_shot(with_light("turn = 60"), "/tmp/shot.toml").source.shot.light.turn_deg,
                  60.0f);
  EXPECT_FLOAT_EQ(parse_shot(minimal(layer), "/tmp/shot.toml").source.shot.light.turn_deg, 0.0f);
  EXPECT_NE(error_of(with_light("turn = 1e9")).find("source.light.turn"), std::string::npos);
}

TEST(ShotFile, KindsSetTheirDefaults) {
  const pipeline::Shot s =
      parse_shot(minimal("[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n"
                         "[layers.ink]\nkind = \"outline\"\nexemplar = \"sphere\"\n"
                         "[layers.dark]\nkind = \"shadow\"\nexemplar = \"sphere\"\n"),
                 "/tmp/shot.toml");
  ASSERT_EQ(s.layers.size(), 3u);
  // File order is kept (toml++ sorts keys; the parser orders by line).
  EXPECT_EQ(s.layers[0].name, "base");
  EXPECT_EQ(s.layers[1].name, "ink");
  EXPECT_EQ(s.layers[2].name, "dark");
  EXPECT_EQ(s.layers[0].look.source, composite::ColorSource::kAlbedo);
  EXPECT_EQ(s.layers[0].mask.kind, pipeline::MaskKind::kCovered);
  EXPECT_EQ(s.layers[1].mask.kind, pipeline::MaskKind::kLines);
  EXPECT_EQ(s.layers[1].look.alpha_from, composite::AlphaFrom::kInverseValue);
  EXPECT_FLOAT_EQ(s.layers[0].temporal.weight, 1.0f);
  EXPECT_FLOAT_EQ(s.layers[0].temporal.uniformity, 1000.0f);
  // Shadow and outline: the warm start alone (docs/design/temporal-default.md).
  EXPECT_FLOAT_EQ(s.layers[1].temporal.weight, 0.0f);
  EXPECT_FLOAT_EQ(s.layers[1].temporal.uniformity, 0.0f);
  EXPECT_FLOAT_EQ(s.layers[2].temporal.weight, 0.0f);
  EXPECT_FLOAT_EQ(s.layers[2].temporal.uniformity, 0.0f);
  // The shadow adds its first frame's uniformity inside large flat areas of its guides.
  EXPECT_FLOAT_EQ(s.layers[2].temporal.flat_uniformity, 3500.0f);
  EXPECT_FLOAT_EQ(s.layers[1].temporal.flat_uniformity, 0.0f);
  EXPECT_FLOAT_EQ(s.layers[0].temporal.flat_uniformity, 0.0f);
  // Shadow and outline pin their ink per covered pixel to a fresh transfer's every 8 frames.
  for (int i : {1, 2}) {
    EXPECT_FLOAT_EQ(s.layers[i].temporal.ink_ratio, 1.0f);
    EXPECT_EQ(s.layers[i].temporal.ink_refresh, 8);
  }
  EXPECT_FLOAT_EQ(s.layers[2].temporal.ink_confident, 1.0f);  // uncovered pixels keep theirs
  EXPECT_FLOAT_EQ(s.layers[1].temporal.ink_confident, 0.5f);
  EXPECT_FLOAT_EQ(s.layers[0].temporal.ink_ratio, 0.0f);
  // The shadow's pin is per object, its references blended between refreshes; not the outline's.
  EXPECT_TRUE(s.layers[2].temporal.ink_objects && s.layers[2].temporal.ink_blend);
  EXPECT_FALSE(s.layers[1].temporal.ink_objects || s.layers[1].temporal.ink_blend);
  // The base's warm start sweeps once after its snap, the other kinds twice.
  EXPECT_EQ(s.layers[0].temporal.coherence_radius, -1);
  EXPECT_EQ(s.layers[0].temporal.warm_patch_match_iters, 1);
  for (int i : {1, 2}) EXPECT_EQ(s.layers[i].temporal.warm_patch_match_iters, 2);
  // Hatching: the town's second style, its ink pinned as the shadow's.
  const pipeline::Layer h =
      parse_shot(minimal("[layers.h]\nkind = \"hatching\"\nexemplar = \"sphere\"\n"),
                 "/tmp/shot.toml")
          .layers[0];
  ASSERT_EQ(h.guides.size(), 3u);
  EXPECT_EQ(h.guides[2].pass, "shadow");
  EXPECT_EQ(h.mask.kind, pipeline::MaskKind::kCovered);
  EXPECT_EQ(h.look.blend, composite::BlendMode::kMultiply);
  EXPECT_FLOAT_EQ(h.temporal.weight, 1.0f);
  EXPECT_EQ(h.temporal.ink_refresh, 8);
  EXPECT_FLOAT_EQ(h.temporal.ink_confident, 1.0f);
  EXPECT_FALSE(h.temporal.ink_objects);
  EXPECT_EQ(h.temporal.warm_patch_match_iters, 2);
  EXPECT_FLOAT_EQ(parse_shot(minimal("[layers.dark]\nkind = \"shadow\"\nexemplar = \"sphere\"\n"
                                     "uniformity = 2000\n"),
                             "/tmp/shot.toml")
                      .layers[0]
                      .temporal.flat_uniformity,
                  2000.0f);
  EXPECT_EQ(s.layers[2].look.blend, composite::BlendMode::kMultiply);
  EXPECT_EQ(s.layers[2].guides[1].pass, "shadow");
  EXPECT_TRUE(s.layers[0].single_colour);
  EXPECT_EQ(s.layers[0].temporal.guide, pipeline::AdvectionGuide::kRestPosition);
  EXPECT_EQ(s.source.width, 64);
  EXPECT_EQ(s.source.shot.last_frame, 3);
}

TEST(ShotFile, GuidesKeepTheFileOrderAndOrderSortsLayers) {
  const pipeline::Shot s = parse_shot(
      minimal(
          "[layers.top]\nexemplar = \"sphere\"\norder = 2\nguides = { shadow = 0.5, normal = 2 }\n"
          "[layers.bottom]\nexemplar = \"sphere\"\norder = 1\nguides = { diffuse = 1 }\n"
          "gradient = [[0, 0, 0, 0], [1, 1, 0.5, 0]]\n"),
      "/tmp/shot.toml");
  EXPECT_EQ(s.layers[0].name, "bottom");
  EXPECT_EQ(s.layers[1].guides[0].pass, "shadow");
  EXPECT_FLOAT_EQ(s.layers[1].guides[1].weight, 2.0f);
  EXPECT_EQ(s.layers[0].look.source, composite::ColorSource::kGradient);
  EXPECT_FLOAT_EQ(s.layers[0].look.gradient[1].color.g, 0.5f);
}

// A shot text and the start of the one-line error it must give.
struct ErrorCase {
  std::string text;
  std::string starts_with;
  std::string contains = "";  // and, when set, a part of it
};

void expect_errors(const std::vector<ErrorCase>& cases) {
  for (const ErrorCase& c : cases) {
    const std::string e = error_of(c.text);
    EXPECT_EQ(e.rfind(c.starts_with, 0), 0u) << "error: " << e << "\nwanted: " << c.starts_with;
    if (!c.contains.empty()) {
      EXPECT_NE(e.find(c.contains), std::string::npos) << e;
    }
  }
}

TEST(ShotFile, ErrorsNameTheKeyPath) {
  const std::string base = "[layers.outline]\nkind = \"outline\"\nexemplar = \"sphere\"\n";
  expect_errors({
      {minimal(base + "wieght = 1\n"), "layers.outline.wieght: unknown key"},
      {minimal(base + "temporal_wieght = 1\n"), "layers.outline.temporal_wieght: unknown key",
       "did you mean 'temporal_weight'"},
      {minimal(base + "opacity = 2\n"), "layers.outline.opacity: must be in [0, 1]"},
      {minimal(base + "levels = [0.5, 0.2, 1]\n"), "layers.outline.levels:"},
      {minimal(base + "guides = { motion = 1 }\n"), "layers.outline.guides.motion:"},
      {minimal(base + "gradient = [[0.5, 0, 0, 0], [0.1, 1, 1, 1]]\n"), "layers.outline.gradient:"},
      {minimal("[layers.a]\nexemplar = \"sphere\"\n"), "layers.a.guides: is required"},
      {minimal("[layers.\"bad name\"]\nkind = \"base\"\nexemplar = \"sphere\"\n"),
       "layers.bad name:"},
      {minimal("[layers.\"\"]\nkind = \"base\"\nexemplar = \"sphere\"\n"),
       "layers.\"\": a layer needs a name"},
  });
}

TEST(ShotFile, ChannelPresetKeysAreChecked) {
  const std::string layer = "[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n";
  std::string scene = minimal(layer);  // a scene source has no channel preset
  scene.insert(scene.find("size"), "preset = \"blender\"\n");
  auto sequence = [&](const std::string& keys) {
    std::string text = minimal(layer);
    const std::size_t from = text.find("scene = "), to = text.find("size = [64, 48]\n");
    return text.replace(from, to + 16 - from,
                        "sequence = \"/nonexistent/frame_%04d.exr\"\nframes = [0, 3]\n" + keys);
  };
  expect_errors({
      {scene, "source.preset: applies to a 'sequence' source only"},
      {sequence("preset = \"maya\"\n"), "source.preset:", "blender"},
      {sequence("view_layer = \"RenderLayer\"\n"),
       "source.view_layer: applies to preset = \"blender\" only"},
      {sequence("preset = \"blender\"\nnormals = \"world\"\n"),
       "source.normals: applies to preset = \"emaki\" only"},
      {sequence("up = \"x\"\n"), "source.up:"},
      // With the keys right, the next error is the missing first frame.
      {sequence("preset = \"blender\"\nview_layer = \"RenderLayer\"\n"),
       "source.sequence: no such file"},
  });
}

// Studio paths run past 80 characters; an error about a file names all of it, file name included.
TEST(ShotFile, ErrorsNameALongPathWhole) {
  const std::string folder = "/nonexistent/" + std::string(150, 'd');
  std::string text = minimal("[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n");
  const std::size_t from = text.find("scene = "), to = text.find("size = [64, 48]\n");
  text.replace(from, to + 16 - from,
               "sequence = \"" + folder + "/frame_%04d.exr\"\nframes = [0, 3]\n");
  expect_errors({{text, "source.sequence: no such file '" + folder + "/frame_0000.exr'"}});
}

// A path over 400 bytes is shown by its head and tail: still one short line ending in the file.
TEST(ShotFile, ErrorsNameAVeryLongPathByItsEnds) {
  const std::string folder = "/nonexistent/" + std::string(1000, 'd');
  std::string text = minimal("[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n");
  const std::size_t from = text.find("scene = "), to = text.find("size = [64, 48]\n");
  text.replace(from, to + 16 - from,
               "sequence = \"" + folder + "/frame_%04d.exr\"\nframes = [0, 3]\n");
  expect_errors({{text, "source.sequence: no such file '/nonexistent/ddd",
                  "...(1028 bytes)..." + std::string(265, 'd') + "/frame_0000.exr' (frame 0)"}});
}

// A device or a FIFO exists: it is "not a regular file", never "no such file"; a FIFO given as
// the shot file is refused without being opened (opening waits for a writer).
TEST(ShotFile, DevicesAndFifosAreNotRegularFiles) {
  std::string text = minimal("[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n");
  const std::string painting = kData + "/stylit/source_style.png";
  text.replace(text.find(painting), painting.size(), "/dev/zero");
  EXPECT_EQ(error_of(text),
            "exemplars.sphere.painting: '/dev/zero' is not a regular file (a device, FIFO or "
            "socket)");
  std::string scene = minimal("[layers.base]\nkind = \"base\"\nexemplar = \"sphere\"\n");
  const std::string fox = kData + "/scenes/Fox.glb";
  scene.replace(scene.find(fox), fox.size(), "/dev/null");
  EXPECT_NE(error_of(scene).find("'/dev/null' is not a regular file"), std::string::npos)
      << error_of(scene);

  const std::string fifo = "/tmp/emaki_shot_file_test_fifo_" + std::to_string(::getpid());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string message;
  try {
    load_shot(fifo);
  } catch (const Error& e) {
    message = e.what();
  }
  ::unlink(fifo.c_str());
  EXPECT_EQ(message, fifo + ": is not a regular file (a device, FIFO or socket)");
  try {
    load_shot("/dev/zero");
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_EQ(message, "/dev/zero: is not a regular file (a device, FIFO or socket)");
}

}  // namespace
}  // namespace emaki::shot
