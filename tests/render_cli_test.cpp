// End-to-end tests of `emaki render` / `emaki template`: outputs on good input; on bad input one
// line on stderr naming the file and the problem, a non-zero exit, and no EXR left behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/image_io.h"
#include "tests/cli_run.h"

namespace {

namespace fs = std::filesystem;
const std::string kEmaki = EMAKI_BINARY;
const std::string kScenes = std::string(EMAKI_TEST_DATA) + "/scenes/";

struct Outcome {
  int exit_code;
  std::string output;  // stderr (and stdout)
};

// args start with the subcommand; stderr and stdout together, as a user sees them.
Outcome run(const std::string& args) {
  const emaki::test::CliResult r = emaki::test::run_cli(kEmaki, emaki::test::split_args(args));
  return {r.exit_code, r.err + r.out};
}

class RenderCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("emaki_render_cli_" + std::to_string(::getpid()) + "_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  int exr_count() const {
    int n = 0;
    if (!fs::exists(dir_ / "out")) return 0;
    for (const auto& e : fs::recursive_directory_iterator(dir_ / "out"))
      if (e.path().string().find(".exr") != std::string::npos) ++n;
    return n;
  }
  // The failure contract: non-zero exit, exactly one line naming `subject` and `what`, no EXR.
  void expect_failure(const std::string& args, const std::string& subject,
                      const std::string& what) {
    const Outcome r = run(args);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(subject), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(what), std::string::npos) << r.output;
    EXPECT_EQ(exr_count(), 0);
  }
  std::string out() const { return (dir_ / "out").string(); }

  fs::path dir_;
};

// A one-triangle glTF; `buffer` and `accessor_count` let a test break it.
std::string triangle_gltf(const std::string& buffer_uri, int accessor_count,
                          const std::string& extra_material = "") {
  return R"({"asset":{"version":"2.0"},"buffers":[{"uri":")" + buffer_uri +
         R"(","byteLength":36}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" +
         std::to_string(accessor_count) +
         R"(,"type":"VEC3","max":[1,1,0],"min":[0,0,0]}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0})" +
         (extra_material.empty() ? "" : ",\"material\":0") + R"(}]}],)" + extra_material +
         R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
}
const char* kTriangleData =
    "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";

TEST_F(RenderCli, RendersFoxFramesWithAllChannels) {
  const Outcome r =
      run("render " + kScenes + "Fox.glb --clip Walk --frames 2-3 --size 96x54 --out " + out() +
          " --previews");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* f : {"frame_0002.exr", "frame_0003.exr"}) {
    const std::vector<std::string> names = emaki::io::list_channels((dir_ / "out" / f).string());
    EXPECT_EQ(names.size(), 24u);
    for (const char* c : {"normal.X", "position_norm.Z", "rest_position.Y", "motion.Y", "alpha.A"})
      EXPECT_NE(std::find(names.begin(), names.end(), c), names.end()) << c;
  }
  EXPECT_TRUE(fs::exists(dir_ / "out" / "preview" / "frame_0002_outline.png"));
}

TEST_F(RenderCli, Triangle) {
  const std::string scene = write("tri.gltf", triangle_gltf(kTriangleData, 3));
  const Outcome r = run("render " + scene + " --size 64x48 --out " + out() + " --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(exr_count(), 1);
}

TEST_F(RenderCli, MissingExternalBuffer) {
  const std::string scene = write("missing.gltf", triangle_gltf("missing.bin", 3));
  expect_failure("render " + scene + " --size 64x48 --out " + out(), "missing.gltf", "missing.bin");
}

TEST_F(RenderCli, AccessorOutOfRange) {
  const std::string scene = write("range.gltf", triangle_gltf(kTriangleData, 30));
  expect_failure("render " + scene + " --size 64x48 --out " + out(), "range.gltf", "out of range");
}

TEST_F(RenderCli, TruncatedGlb) {
  std::ifstream in(kScenes + "Fox.glb", std::ios::binary);
  std::string head(4000, '\0');
  in.read(head.data(), head.size());
  const std::string scene = write("truncated.glb", head);
  expect_failure("render " + scene + " --size 64x48 --out " + out(), "truncated.glb",
                 "not a valid glTF");
}

TEST_F(RenderCli, TextureThatDoesNotDecode) {
  const std::string material =
      R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
      R"("textures":[{"source":0}],"images":[{"uri":"data:image/png;base64,iVBORw0KGgoAAAAAAAAAAAAA"}],)";
  const std::string scene = write("texture.gltf", triangle_gltf(kTriangleData, 3, material));
  expect_failure("render " + scene + " --size 64x48 --out " + out(), "texture.gltf", "image");
}

TEST_F(RenderCli, RequiredExtensionNotSupported) {
  std::string text = triangle_gltf(kTriangleData, 3);
  text.insert(1, R"("extensionsUsed":["KHR_draco_mesh_compression"],)"
                 R"("extensionsRequired":["KHR_draco_mesh_compression"],)");
  const std::string scene = write("draco.gltf", text);
  expect_failure("render " + scene + " --size 64x48 --out " + out(), "draco.gltf",
                 "KHR_draco_mesh_compression");
}

TEST_F(RenderCli, TooManySamples) {
  expect_failure("render " + kScenes + "Fox.glb --size 16000x9000 --aa 3 --out " + out(),
                 "emaki render: error: --aa: ", "lower the antialiasing or the size");
}

TEST_F(RenderCli, EmptyScene) {
  const std::string scene =
      write("empty.gltf",
            R"({"asset":{"version":"2.0"},"nodes":[{}],"scenes":[{"nodes":[0]}],"scene":0})");
  expect_failure("render " + scene + " --size 64x48 --out " + out(), "empty.gltf",
                 "no triangle mesh");
}

TEST_F(RenderCli, FrameRangeOutsideTheClip) {
  expect_failure(
      "render " + kScenes + "Fox.glb --clip Walk --frames 0-500 --size 64x48 --out " + out(),
      "--frames", "past the end of clip 'Walk'");
}

// The renderer names a neutral field ("clip", "start", "gltf_node"); the command line re-spells
// it as the option the user typed.
TEST_F(RenderCli, RendererErrorsNameTheirOption) {
  const std::string fox = "render " + kScenes + "Fox.glb --size 64x48 --out " + out();
  expect_failure(fox + " --clip Nope", "emaki render: error: --clip: ", "no clip 'Nope'");
  expect_failure(fox + " --clip Walk --start 1000",
                 "emaki render: error: --start: ", "outside clip 'Walk'");
  expect_failure(fox + " --clip Walk --frames 0-500",
                 "emaki render: error: --frames: ", "past the end of clip 'Walk'");
  expect_failure(fox + " --gltf-camera 0",
                 "emaki render: error: --gltf-camera: ", "is not a camera node");
}

TEST_F(RenderCli, CameraSeesNothing) {
  expect_failure(
      "render " + kScenes +
          "Fox.glb --frames 0-2 --camera 0,50,5000 --target 0,50,10000 --size 64x48 --out " + out(),
      "Fox.glb", "all background");
}

TEST_F(RenderCli, MissingFile) {
  expect_failure("render " + (dir_ / "nope.glb").string() + " --out " + out(), "nope.glb",
                 "no such file");
}

TEST_F(RenderCli, BadSizeNamesTheOption) {
  expect_failure("render " + kScenes + "Fox.glb --size 64by48 --out " + out(), "--size",
                 "WIDTHxHEIGHT");
}

TEST_F(RenderCli, TemplateWritesPassesAndPaintTemplate) {
  const Outcome r = run("template --size 120x90 --out " + out());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "reference.exr"));
  EXPECT_TRUE(fs::exists(dir_ / "out" / "template.png"));
  EXPECT_EQ(emaki::io::list_channels((dir_ / "out" / "reference.exr").string()).size(), 24u);
}

TEST_F(RenderCli, TemplateFitNeedsTheSphere) {
  expect_failure(
      "template --fit " + std::string(EMAKI_TEST_DATA) + "/stylit/source_style.png --out " + out(),
      "--sphere", "required");
}

}  // namespace
