// glTF 2.0 (.gltf with embedded or external buffers, .glb) into an in-memory scene::Scene,
// through Debian's tinygltf. Base-colour textures are decoded to linear float on load.
//
// Scene files come from other people and are loaded unattended on a farm, so every size,
// count, offset and index in them is checked (with overflow-checked arithmetic) before it is
// used, and the loader refuses what would make it allocate or loop without bound. The limits:
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "scene/scene.h"

namespace emaki::io {

// Nesting of JSON arrays / objects. tinygltf's JSON parser recurses per level, so a file of
// 200k '[' overflows the stack; real glTF nests fewer than 20 levels.
inline constexpr int kMaxJsonDepth = 512;
// JSON arrays + objects in one file. Each becomes a tinygltf struct of up to ~1 KB (a file of
// 20 MB of "{}," would otherwise take gigabytes); a scene with 100k nodes has ~500k.
inline constexpr int64_t kMaxJsonContainers = int64_t(1) << 21;
// The scene file and each external buffer / image file.
inline constexpr int64_t kMaxFileBytes = int64_t(1) << 30;
// Vertices (POSITION elements) and triangles over all mesh primitives of the file, and again
// over every drawn instance of them (a mesh drawn by 1000 nodes counts 1000 times): what the
// renderer holds per frame grows with these (about 250 bytes a drawn vertex and 200 a drawn
// triangle: 4M of each stays under 2 GB).
inline constexpr int64_t kMaxVertices = int64_t(1) << 22;
inline constexpr int64_t kMaxTriangles = int64_t(1) << 22;
// Numbers (floats or integers) read from accessors over the whole file: attributes, indices,
// morph targets, skins, animation keys. 2^26 is 256 MiB of floats.
inline constexpr int64_t kMaxAccessorValues = int64_t(1) << 26;
// Elements of an accessor without a buffer view. Such an accessor is all zeros (its data would
// come from sparse storage or an extension, neither of which is read), so a large one is only
// a way for a tiny file to ask for millions of vertices.
inline constexpr int64_t kMaxZeroAccessorElements = 65536;
// Morph targets per primitive (and weights per key of a weights animation).
inline constexpr int kMaxMorphTargets = 4096;
// Joints per skin: JOINTS_0 holds 8- or 16-bit indices.
inline constexpr int kMaxSkinJoints = 65536;
// Animation key times, seconds: finite, non-decreasing, |t| <= this (frames stay in int range).
inline constexpr double kMaxKeyTime = 1e6;
// Decoded base-colour texture pixels over the scene (each also within the --max-pixels budget):
// textures are held as float RGBA, 2^25 pixels are 512 MiB.
inline constexpr int64_t kMaxTexturePixels = int64_t(1) << 25;

struct GltfOptions {
  // Read buffers and images whose uri leads outside the scene file's folder ("../x.bin",
  // "/abs/path.bin", or a symbolic link out of it). Off by default: such a uri is an error that
  // names it (`emaki render --allow-outside-paths` turns it on). data: uris are always allowed.
  bool allow_outside_paths = false;
};

// Throws emaki::Error naming the file and what is wrong with it: unreadable or truncated file,
// missing external buffer, accessor out of its buffer's range, texture that does not decode,
// a node hierarchy that is not a forest (cycles, two parents), non-finite numbers, a limit above
// exceeded, a scene with no triangle meshes.
scene::Scene load_gltf(const std::string& path, const GltfOptions& options = {});

// The same from bytes in memory (a .glb or .gltf text, told apart by the magic). `name` is the
// subject of errors; relative uris resolve against `base_dir`, and with an empty `base_dir` no
// external file is read at all (only data: uris and the GLB's own buffer).
scene::Scene load_gltf_from_memory(std::string_view bytes, const std::string& name,
                                   const std::string& base_dir, const GltfOptions& options = {});

// The pre-scan that keeps deep or huge JSON away from tinygltf: the deepest nesting of arrays
// and objects in `json` and how many there are (brackets inside strings do not count).
struct JsonShape {
  int max_depth = 0;
  int64_t containers = 0;
};
JsonShape scan_json_shape(std::string_view json);

}  // namespace emaki::io
