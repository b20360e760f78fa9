// Hostile glTF scenes through `emaki render`: each must fail with exit 1, no signal, within the
// 60 s / 2 GiB bound of run_cli, one line on stderr naming the file and the problem, and no
// output left behind. The small reproducers live in tests/data/hostile/gltf/ (the gltf fuzzer
// replays them too); large or path-dependent ones are written here at run time.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli_run.h"
#include "tests/small_painting.h"
#include "tests/textured_triangle.h"

namespace {

namespace fs = std::filesystem;
using emaki::test::CliResult;
using emaki::test::count_lines;
using emaki::test::run_cli;

const std::string kEmaki = EMAKI_BINARY;
const fs::path kHostile = fs::path(EMAKI_HOSTILE) / "gltf";

class HostileGltf : public ::testing::Test {
 protected:
  fs::path write(const fs::path& rel, const std::string& bytes) {
    const fs::path p = dir_ / rel;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
  }
  CliResult render(const fs::path& scene, const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"render", scene.string(), "--size", "32x24",
                                     "--out",  out().string(), "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    emaki::test::CliOptions options;
    options.cwd = cwd_;
    return run_cli(kEmaki, args, options);
  }
  fs::path out() const { return dir_ / "out"; }
  bool out_is_empty() const { return !fs::exists(out()) || fs::is_empty(out()); }

  // The failure contract, with `what` a piece of the expected message.
  void expect_refused(const fs::path& scene, const std::string& what,
                      const std::vector<std::string>& extra = {}) {
    const CliResult r = render(scene, extra);
    EXPECT_FALSE(r.timed_out) << scene;
    EXPECT_EQ(r.signal, 0) << scene << "\n" << r.err;
    EXPECT_EQ(r.exit_code, 1) << scene << "\n" << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err.substr(0, 2000);
    EXPECT_LT(r.err.size(), 600u) << r.err.substr(0, 2000);
    EXPECT_NE(r.err.find(scene.filename().string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(what), std::string::npos) << "expected '" << what << "' in\n" << r.err;
    EXPECT_TRUE(out_is_empty()) << scene;
  }

  emaki::test::TempDir tmp_{
      "hostile_gltf_" +
      std::string(::testing::UnitTest::GetInstance()->current_test_info()->name())};
  fs::path dir_ = tmp_.path();
  fs::path cwd_;  // empty: the test's own
};

// A one-triangle scene; `buffer_uri` and `name` let a test break it.
std::string triangle(const std::string& buffer_uri, const std::string& mesh_name = "tri",
                     const std::string& extra = "") {
  return R"({"asset":{"version":"2.0"},"buffers":[{"uri":")" + buffer_uri +
         R"(","byteLength":36}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
         R"("meshes":[{"name":")" +
         mesh_name + R"(","primitives":[{"attributes":{"POSITION":0}}]}],)" + extra +
         R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
}
const std::string kTriangleData =
    "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
// The same 36 bytes as a file.
std::string triangle_bytes() {
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  return std::string(reinterpret_cast<const char*>(v), sizeof v);
}

std::string glb(std::string json) {
  while (json.size() % 4) json += ' ';
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  return "glTF" + u32(2) + u32(uint32_t(20 + json.size())) + u32(uint32_t(json.size())) + "JSON" +
         json;
}

struct Case {
  const char* file;
  const char* what;
};

// ---- Committed reproducers ----

const Case kCases[] = {
    // Counts and offsets that wrap 64-bit arithmetic, or ask for more than the limits.
    {"count_wrap.gltf", "has count 4611686018427387904"},
    {"view_offset_wrap.gltf",
     "buffer view 0 (offset 18446744073709551600, length 36) is out of range"},
    {"accessor_offset_wrap.gltf", "is out of range"},
    // Found by the gltf fuzzer: a count of 0 skipped the range check (UBSan: pointer overflow).
    {"fuzz_empty_accessor_offset.gltf", "0 elements of 12 bytes from offset 18446744073709551612"},
    {"stride_too_small.gltf", "byteStride 4"},
    {"index_out_of_range.gltf", "has index 7 but only 3 vertices"},
    {"zero_accessor_huge.gltf", "more than 67108864 values"},
    // Found by the gltf fuzzer: 4M zero vertices from a 444-byte file took 30 s to pose.
    {"fuzz_timeout_zero_accessor.gltf", "has no buffer view"},
    {"instances_over_budget.gltf", "counting each instance of a mesh"},
    {"ibm_count_wrap.gltf", "skin 0 inverseBindMatrices (accessor 1) has count"},
    {"morph_count_wrap.gltf", "morph target 0 POSITION (accessor 1) has count"},
    {"anim_input_count_wrap.gltf", "has count 18446744073709551615"},
    {"joint_out_of_range.gltf", "uses joint 9 but skin 0 has 1 joints"},
    // Node graphs that are not a forest.
    {"node_cycle.gltf", "node hierarchy has a cycle"},
    {"node_self_child.gltf", "node 0 lists itself as a child"},
    {"node_two_parents.gltf", "node 2 has two parents (nodes 0 and 1)"},
    {"scene_root_twice.gltf", "scene 0 lists node 0 twice"},
    {"skin_joint_cycle.gltf", "node hierarchy has a cycle"},
    {"child_index_out_of_range.gltf", "node 0 lists child 5"},
    // Non-finite or absurd numbers.
    {"nan_position.gltf", "POSITION (accessor 0) holds a non-finite value"},
    {"inf_position.gltf", "POSITION (accessor 0) holds a non-finite value"},
    {"huge_position_overflow.gltf", "posed positions must be finite"},
    {"huge_translation.gltf", "node 0 ('') has a non-finite translation"},
    {"huge_matrix.gltf", "node 0 ('') has a non-finite matrix"},
    {"nan_key_time.gltf", "input (accessor 1) holds a non-finite value"},
    {"inf_key_time.gltf", "input (accessor 1) holds a non-finite value"},
    {"huge_key_time.gltf", "key times must be finite and within"},
    {"decreasing_key_times.gltf", "key times that decrease"},
    {"nan_key_value.gltf", "output (accessor 2) holds a non-finite value"},
    {"camera_bad_fov.gltf", "camera 0"},
    // Images: checked from the header, before any decoding.
    {"image_huge_header.gltf", "100000x100000 pixels, over the pixel budget"},
    {"image_not_png.gltf", "neither a PNG nor a JPEG"},
    {"image_view_out_of_range.gltf", "is out of range of buffer 0"},
    // Paths out of the scene's folder (the file does not exist: nothing is read).
    {"buffer_uri_outside.gltf", "secret.bin"},
    // GLB containers whose lengths point past the file.
    {"glb_bin_chunk_overrun.glb", "second chunk runs past its end"},
    {"glb_length_past_end.glb", "the GLB header says 1073741824 bytes"},
    {"glb_json_length_past_end.glb", "not a valid glTF file"},
};

TEST_F(HostileGltf, CommittedReproducersFailCleanly) {
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.file);
    ASSERT_TRUE(fs::exists(kHostile / c.file)) << c.file;
    expect_refused(kHostile / c.file, c.what);
  }
}

// Every reproducer in the folder is in the table: a new one cannot be added untested.
TEST_F(HostileGltf, EveryReproducerIsCovered) {
  for (const auto& e : fs::directory_iterator(kHostile)) {
    const std::string name = e.path().filename().string();
    if (e.path().extension() == ".md") continue;
    bool found = name == "zero_vertices.gltf";  // AllZeroVerticesSeeNothing
    for (const Case& c : kCases) found = found || name == c.file;
    EXPECT_TRUE(found) << name << " is not in kCases";
  }
}

// An all-zero mesh used to reach signed overflow in the rasteriser (NaN camera); now nothing is
// drawn and the command says so. Documented outcome: exit 1, "the camera sees nothing".
TEST_F(HostileGltf, AllZeroVerticesSeeNothing) {
  expect_refused(kHostile / "zero_vertices.gltf", "the camera sees nothing");
}

// ---- Generated at run time ----

TEST_F(HostileGltf, DeeplyNestedJson) {
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  expect_refused(write("deep.gltf", R"({"asset":{"version":"2.0"},"extras":)" + deep + "}"),
                 "nests 200001 levels deep");
  expect_refused(write("deep.glb", glb(R"({"asset":{"version":"2.0"},"extras":)" + deep + "}")),
                 "nests 200001 levels deep");
  // Brackets inside strings (and escaped quotes) are not nesting.
  const std::string quoted = "\"\\\"" + std::string(100000, '[') + "\"";
  const CliResult r =
      render(write("quoted.gltf", triangle(kTriangleData, "tri", R"("extras":)" + quoted + ",")));
  EXPECT_EQ(r.exit_code, 0) << r.err.substr(0, 500);
}

TEST_F(HostileGltf, TooManyJsonContainers) {
  std::string nodes;
  for (int i = 0; i < 2200000; ++i) nodes += i ? ",{}" : "{}";
  expect_refused(write("wide.gltf", R"({"asset":{"version":"2.0"},"nodes":[)" + nodes + "]}"),
                 "arrays and objects");
}

TEST_F(HostileGltf, BufferUriOutsideTheSceneFolder) {
  write("secret.bin", triangle_bytes());
  const fs::path scene = write("scene/up.gltf", triangle("../secret.bin"));
  expect_refused(scene, "leads outside the scene's folder");
  // The option reads it.
  const CliResult r = render(scene, {"--allow-outside-paths"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// tinygltf looks for a uri under the scene's folder, then under the working directory: from
// "/", an absolute uri is found there (and used to be read).
TEST_F(HostileGltf, AbsoluteBufferUri) {
  cwd_ = "/";
  const fs::path secret = write("secret.bin", triangle_bytes());
  expect_refused(write("scene/abs.gltf", triangle(secret.string())),
                 "leads outside the scene's folder");
}

TEST_F(HostileGltf, SymlinkOutOfTheSceneFolder) {
  const fs::path secret = write("secret.bin", triangle_bytes());
  const fs::path scene = write("scene/link.gltf", triangle("inside.bin"));
  fs::create_symlink(secret, dir_ / "scene" / "inside.bin");
  expect_refused(scene, "leads outside the scene's folder");
}

TEST_F(HostileGltf, ImageUriOutsideTheSceneFolder) {
  write("secret.png", "\x89PNG");
  const std::string material =
      R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
      R"("textures":[{"source":0}],"images":[{"uri":"../secret.png"}],)";
  std::string text = triangle(kTriangleData, "tri", material);
  text.replace(text.find(R"("attributes":{"POSITION":0})"), 27,
               R"("attributes":{"POSITION":0},"material":0)");
  expect_refused(write("scene/image.gltf", text), "secret.png");
}

TEST_F(HostileGltf, DeviceFileUri) {
  cwd_ = "/";
  const fs::path scene = write("scene/dev.gltf", triangle("/dev/zero"));
  expect_refused(scene, "leads outside the scene's folder");
  expect_refused(scene, "not a regular file", {"--allow-outside-paths"});
}

TEST_F(HostileGltf, FilesInsideTheFolderStillLoad) {
  write("scene/data/tri.bin", triangle_bytes());
  const CliResult r = render(write("scene/ok.gltf", triangle("data/tri.bin")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A 1 MB name from the file is cut in the error line.
TEST_F(HostileGltf, LongNamesAreCut) {
  const std::string name(1 << 20, 'x');
  std::string text = triangle(kTriangleData, name);
  text.replace(text.find(R"("count":3)"), 9, R"("count":30)");
  expect_refused(write("long.gltf", text), "(1048576 bytes)");
}

// tinygltf quotes whole data: uris in its messages; the line stays short.
TEST_F(HostileGltf, LongDataUriInTinygltfMessage) {
  const std::string uri = "data:application/octet-stream;base64," + std::string(1 << 20, 'A');
  expect_refused(write("longuri.gltf", triangle(uri)), "not a valid glTF file");
}

// source.objects: 256 objects of one file whose 2048 x 2048 texture decodes to 64 MiB, half of
// them through a link to it. The file is loaded once and its texture held once, so the run fits
// the 2 GiB bound; before, each link was another file and every object cloned the texture
// (16 GiB).
TEST_F(HostileGltf, ACrowdOfOneTexturedFileHoldsItsTextureOnce) {
  const std::string tri = emaki::test::write_textured_triangle(dir_, 2048);
  fs::create_symlink(tri, dir_ / "link.gltf");
  emaki::test::write_small_painting(std::string(EMAKI_TEST_DATA) + "/stylit/source_style.png",
                                    (dir_ / "painting.png").string());
  std::string text = "[source]\nframes = [0, 0]\nsize = [32, 24]\naa = 1\n";
  for (int i = 0; i < 256; ++i)
    text += "[[source.objects]]\nscene = \"" + std::string(i % 2 ? "tri.gltf" : "link.gltf") +
            "\"\ntranslate = [" + std::to_string(i % 16) + ", " + std::to_string(i / 16) + ", 0]\n";
  text +=
      "[exemplars.sphere]\npainting = \"painting.png\"\n[layers.base]\nkind = \"base\"\n"
      "exemplar = \"sphere\"\n[outputs]\nfolder = \"out\"\nmp4 = false\n"
      "contact_sheet = false\n";
  const fs::path shot = write("crowd.toml", text);
  const CliResult r = run_cli(kEmaki, {"run", shot.string()});
  EXPECT_EQ(r.exit_code, 0) << r.err.substr(0, 2000);
  EXPECT_EQ(r.signal, 0);
  EXPECT_TRUE(fs::exists(dir_ / "out/composite/frame_0000.png"));
}

}  // namespace
