// libFuzzer target for the glTF loader and the scene code it feeds: the bytes are a .glb or
// .gltf loaded from memory (no external file is ever read), then the scene is posed at a few
// times of its first clip and a tiny frame is rendered. emaki::Error is the expected outcome
// of bad input; anything else escaping, a sanitizer report, a leak, a timeout or an OOM is a
// bug.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "io/gltf_loader.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "scene/staging.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace emaki;
  try {
    const scene::Scene s = io::load_gltf_from_memory(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.gltf", "");
    std::size_t vertices = 0;
    for (const auto& m : s.meshes)
      for (const auto& p : m.primitives) vertices += p.positions.size();
    const int clip = s.animations.empty() ? -1 : 0;
    const float t0 = clip < 0 ? 0.0f : s.animations[0].start;
    const float t1 = clip < 0 ? 0.0f : s.animations[0].end;
    // Posing and rendering are linear in the geometry; big inputs are posed once and not
    // drawn, to keep the executions per second up (the loader's limits bound them anyway).
    if (vertices > 20000) {
      scene::pose_scene(s, clip, t1);
      return 0;
    }
    for (float t : {t0, 0.5f * (t0 + t1), t1, t1 + 1.0f}) scene::pose_scene(s, clip, t);
    scene::ShotSpec shot;
    shot.first_frame = shot.last_frame = 0;
    render::RenderOptions options;
    options.width = 24;
    options.height = 16;
    options.aa = 1;
    options.shadow_map_size = 64;
    const render::ShotRenderer renderer(s, shot, options);
    renderer.render(0);
  } catch (const Error&) {
  }
  return 0;
}
