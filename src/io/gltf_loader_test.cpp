// Unit tests of the glTF loader's guards: the JSON pre-scan, the node-graph checks and the
// in-memory entry point (which reads no external file).
#include "io/gltf_loader.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace emaki::io {
namespace {

TEST(JsonShape, CountsNestingAndContainers) {
  EXPECT_EQ(scan_json_shape("{}").max_depth, 1);
  EXPECT_EQ(scan_json_shape(R"({"a":[[1],[2,{"b":[]}]]})").max_depth, 5);
  EXPECT_EQ(scan_json_shape(R"({"a":[[1],[2,{"b":[]}]]})").containers, 6);
  EXPECT_EQ(scan_json_shape("[[[]]][]").max_depth, 3);
}

TEST(JsonShape, BracketsInStringsDoNotCount) {
  EXPECT_EQ(scan_json_shape(R"({"a":"[[[[{{{{"})").max_depth, 1);
  // An escaped quote does not end the string; an escaped backslash does not escape the quote.
  EXPECT_EQ(scan_json_shape(R"({"a":"\"[[[["})").max_depth, 1);
  EXPECT_EQ(scan_json_shape(R"({"a":"\\",  "b":[[]]})").max_depth, 3);
}

TEST(JsonShape, DeepInputIsLinear) {
  const std::string deep = std::string(1000000, '[') + std::string(1000000, ']');
  const JsonShape s = scan_json_shape(deep);
  EXPECT_EQ(s.max_depth, 1000000);
  EXPECT_EQ(s.containers, 1000000);
}

// A one-triangle scene with the given "nodes" and "scenes" members.
std::string scene_with(const std::string& nodes, const std::string& scenes) {
  return R"({"asset":{"version":"2.0"},"buffers":[{"uri":"data:application/octet-stream;base64,)"
         R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA","byteLength":36}],)"
         R"("bufferViews":[{"buffer":0,"byteLength":36}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":)" +
         nodes + R"(,"scenes":)" + scenes + R"(,"scene":0})";
}

std::string load_error(const std::string& text) {
  try {
    load_gltf_from_memory(text, "mem.gltf", "");
  } catch (const Error& e) {
    EXPECT_EQ(e.subject(), "mem.gltf");
    return e.what();
  }
  return "";
}

TEST(GltfFromMemory, LoadsATriangle) {
  const scene::Scene s =
      load_gltf_from_memory(scene_with(R"([{"mesh":0}])", R"([{"nodes":[0]}])"), "mem.gltf", "");
  EXPECT_EQ(s.source, "mem.gltf");
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_EQ(s.meshes[0].primitives[0].positions.size(), 3u);
  EXPECT_EQ(s.roots, std::vector<int>{0});
}

TEST(GltfNodeGraph, CycleOfTwo) {
  EXPECT_NE(load_error(scene_with(R"([{"mesh":0},{"children":[2]},{"children":[1]}])",
                                  R"([{"nodes":[0]}])"))
                .find("has a cycle"),
            std::string::npos);
}

TEST(GltfNodeGraph, LongCycle) {
  std::string nodes = R"([{"mesh":0})";
  for (int i = 1; i <= 1000; ++i)
    nodes += R"(,{"children":[)" + std::to_string(i == 1000 ? 1 : i + 1) + "]}";
  EXPECT_NE(load_error(scene_with(nodes + "]", R"([{"nodes":[0]}])")).find("has a cycle"),
            std::string::npos);
}

TEST(GltfNodeGraph, TwoParentsAndSelfChild) {
  EXPECT_NE(load_error(scene_with(R"([{"children":[2]},{"children":[2]},{"mesh":0}])",
                                  R"([{"nodes":[0,1]}])"))
                .find("node 2 has two parents"),
            std::string::npos);
  EXPECT_NE(load_error(scene_with(R"([{"mesh":0,"children":[0]}])", R"([{"nodes":[0]}])"))
                .find("lists itself"),
            std::string::npos);
}

// Exporters list child nodes as scene roots; such a node is drawn once, through its parent.
TEST(GltfNodeGraph, ListedChildIsNotARootOfItsOwn) {
  const scene::Scene s = load_gltf_from_memory(
      scene_with(R"([{"children":[1]},{"mesh":0}])", R"([{"nodes":[0,1]}])"), "mem.gltf", "");
  EXPECT_EQ(s.roots, std::vector<int>{0});
  const scene::Scene t = load_gltf_from_memory(
      scene_with(R"([{"children":[1]},{"mesh":0}])", R"([{"nodes":[1]}])"), "mem.gltf", "");
  EXPECT_EQ(t.roots, std::vector<int>{1});
}

TEST(GltfFromMemory, ReadsNoExternalFile) {
  std::string text = scene_with(R"([{"mesh":0}])", R"([{"nodes":[0]}])");
  const std::string data =
      text.substr(text.find("data:"), text.find("\",\"byteLength") - text.find("data:"));
  text.replace(text.find(data), data.size(), "/etc/hostname");
  EXPECT_NE(load_error(text).find("scene loaded from memory cannot read"), std::string::npos);
}

}  // namespace
}  // namespace emaki::io
