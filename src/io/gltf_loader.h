// glTF 2.0 (.gltf with embedded or external buffers, .glb) into an in-memory scene::Scene,
// through Debian's tinygltf. Base-colour textures are decoded to linear float on load.
#pragma once

#include <string>

#include "scene/scene.h"

namespace emaki::io {

// Throws emaki::Error naming the file and what is wrong with it: unreadable or truncated file,
// missing external buffer, accessor out of its buffer's range, texture that does not decode,
// a scene with no triangle meshes.
scene::Scene load_gltf(const std::string& path);

}  // namespace emaki::io
