// Seconds per frame of the guide-pass renderer: Fox.glb walking, 1920x1080, all passes, default
// antialiasing (RenderOptions{}). Usage: render_bench [FOX.glb] [frames] [WxH]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "core/error.h"
#include "core/parallel.h"
#include "core/performance.h"
#include "io/gltf_loader.h"
#include "render/renderer.h"

int main(int argc, char** argv) {
  emaki::set_performance(emaki::performance_from_environment());  // as `emaki` does
  using namespace emaki;
  const std::string path =
      argc > 1 ? argv[1] : std::string(EMAKI_SOURCE_DIR) + "/examples/data/Fox.glb";
  const int frames = argc > 2 ? std::atoi(argv[2]) : 8;
  render::RenderOptions options;
  options.width = 1920;
  options.height = 1080;
  if (argc > 3) std::sscanf(argv[3], "%dx%d", &options.width, &options.height);
  try {
    const scene::Scene s = io::load_gltf(path);
    scene::ShotSpec shot;
    shot.clip = "Walk";
    shot.last_frame = 16;
    shot.camera.orbit_deg = 30.0f;
    const render::ShotRenderer renderer(s, shot, options);
    renderer.render(0);  // warm-up: arena, page faults
    // CPU time too: on a shared machine the wall time says as much about the neighbours.
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    for (int i = 0; i < frames; ++i) renderer.render(1 + i % 16);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    std::printf(
        "render_bench: %s %dx%d aa %dx%d, %d passes (%d channels), %d threads: "
        "%.3f s/frame (wall), %.3f CPU s/frame, over %d frames\n",
        path.c_str(), options.width, options.height, options.aa, options.aa, 13,
        render::kChannelCount, thread_count(), seconds / frames, cpu / frames, frames);
  } catch (const Error& e) {
    std::fprintf(stderr, "render_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
