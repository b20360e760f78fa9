// Seconds per frame of a whole shot: the bundled example (examples/fox/shot.toml: base, shadow
// and outline layers, temporal on) at a chosen size, frames kept in memory (no output files),
// so the figure is rendering + synthesis + advection + compositing.
//
//   shot_bench [--digest] [--one-layer-at-a-time] [WIDTHxHEIGHT=1920x1080] [FRAMES=3] [THREADS=0]
//
// Frame 0 has no temporal guide; the figure that matters is the mean of the later frames. The
// split of those frames by step follows: as `emaki run` does, the frame's layers are synthesized
// at once ("layers", with the frame's rendering and advection); with --one-layer-at-a-time, as
// `emaki run --one-layer-at-a-time` does, one after another, each layer its own step (the first
// layer's includes the frame's rendering and every layer's advection). "compositing" runs from
// the composite's start to the next frame.
// With --digest it also prints a digest of every layer frame and composited frame (equal
// digests, equal results); computing it adds to the frames' times. Like `emaki`, it starts
// itself again with huge pages where the kernel takes advice (apps/emaki/huge_pages.h;
// GLIBC_TUNABLES=glibc.malloc.hugetlb=0 measures without them).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "apps/emaki/huge_pages.h"
#include "core/parallel.h"
#include "core/performance.h"
#include "memory_store.h"
#include "pipeline/run.h"
#include "shot/api.h"
#include "shot/inputs.h"

namespace {

// The leading flags; false on one it does not know.
bool take_flags(int& argc, char**& argv, bool& digest, bool& one_layer) {
  for (; argc > 1 && std::string(argv[1]).starts_with("--"); --argc, ++argv) {
    const std::string flag = argv[1];
    if (flag == "--digest")
      digest = true;
    else if (flag == "--one-layer-at-a-time")
      one_layer = true;
    else
      return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  emaki::app::restart_with_huge_pages(argv, "run");               // as `emaki run` does
  emaki::set_performance(emaki::performance_from_environment());  // as `emaki` does
  using namespace emaki;
  int width = 1920, height = 1080, frames = 3, threads = 0;
  bool digest = false, one_layer = false;
  if (!take_flags(argc, argv, digest, one_layer) ||
      (argc > 1 && std::sscanf(argv[1], "%dx%d", &width, &height) != 2)) {
    std::fprintf(stderr,
                 "usage: shot_bench [--digest] [--one-layer-at-a-time] [WIDTHxHEIGHT] [FRAMES] "
                 "[THREADS]\n");
    return 2;
  }
  if (argc > 2) frames = std::max(2, std::atoi(argv[2]));
  if (argc > 3) threads = std::atoi(argv[3]);
  const ScopedThreadCount count(threads);
  try {
    pipeline::Shot shot = shot::open(std::string(EMAKI_SOURCE_DIR) + "/examples/fox/shot.toml");
    shot.source.width = shot.source.render.width = width;
    shot.source.height = shot.source.render.height = height;
    shot.source.last_frame = shot.source.first_frame + frames - 1;
    shot.source.shot.last_frame = shot.source.last_frame;
    const auto source = shot::open_frames(shot);
    const auto exemplars = shot::load_exemplars(shot);
    const pipeline::CompositeInputs ci = shot::load_composite_inputs(shot);
    bench::MemoryStore store(digest);
    std::vector<double> seconds;
    auto t = std::chrono::steady_clock::now();
    int last = -1;
    pipeline::RunOptions o;
    o.concurrent_layers = !one_layer;  // as `emaki run` does
    // Steps (a layer, or compositing) of the temporal frames: each runs from its progress tick
    // to the next one.
    std::vector<std::string> order;
    std::map<std::string, double> step_seconds;
    std::string step;
    int step_frame = -1;
    auto step_t = std::chrono::steady_clock::now();
    auto end_step = [&](std::chrono::steady_clock::time_point now) {
      if (step_frame > shot.source.first_frame) {
        if (!step_seconds.count(step)) order.push_back(step);
        step_seconds[step] += std::chrono::duration<double>(now - step_t).count();
      }
    };
    // Frame boundaries from the progress callback: a frame ends when its compositing starts.
    o.progress = [&](const pipeline::Progress& p) {
      const auto now = std::chrono::steady_clock::now();
      end_step(now);
      step = p.layer.empty() ? "compositing" : one_layer ? p.layer : "layers";
      step_frame = p.frame;
      step_t = now;
      if (!p.layer.empty() || p.frame == last) return;
      last = p.frame;
      seconds.push_back(std::chrono::duration<double>(now - t).count());
      t = now;
    };
    pipeline::run_shot(shot, *source, exemplars, ci, store, o);
    end_step(std::chrono::steady_clock::now());
    double later = 0;
    for (std::size_t i = 1; i < seconds.size(); ++i) later += seconds[i];
    std::printf(
        "shot_bench: %dx%d, %zu layers, %d threads: frame 0 (no temporal) %.2f s; "
        "frames 1-%d (temporal) %.2f s per frame\n",
        width, height, shot.layers.size(), thread_count(), seconds[0], frames - 1,
        later / double(seconds.size() - 1));
    std::printf("shot_bench: per temporal frame:");
    for (const std::string& name : order)
      std::printf(" %s %.2f s", name.c_str(), step_seconds[name] / double(frames - 1));
    std::printf("\n");
    if (digest)
      std::printf("shot_bench: digest of the layer and composited frames %016llx\n",
                  static_cast<unsigned long long>(store.digest()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shot_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
