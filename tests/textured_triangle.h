// A small glTF asset with a large texture, for the tests of a scene's memory: one triangle whose
// material reads a side x side base-colour texture (a constant PNG of a few kilobytes that
// decodes to side x side x 16 bytes of float RGBA).
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include "core/image.h"
#include "io/image_io.h"

namespace emaki::test {

// Writes `folder`/tri.gltf and its texture `folder`/tri.png; returns the .gltf's path.
inline std::string write_textured_triangle(const std::filesystem::path& folder, int side) {
  Image<float> texture(side, side, 3);
  texture.fill(0.5f);
  io::WriteOptions wo;
  wo.format = io::SampleFormat::kU8;
  io::write_image((folder / "tri.png").string(), texture.cview(), wo);
  // Three vertices (0,0,0), (1,0,0), (0,1,0) as little-endian floats, base64.
  const std::string positions =
      "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
  const std::string path = (folder / "tri.gltf").string();
  std::ofstream(path)
      << R"({"asset":{"version":"2.0"},"buffers":[{"uri":")" << positions
      << R"(","byteLength":36}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
      << R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
      << R"("images":[{"uri":"tri.png"}],"textures":[{"source":0}],)"
      << R"("materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
      << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],)"
      << R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  return path;
}

}  // namespace emaki::test
