// The cost of colour management per frame, the most a shot can ask for, measured on what
// `emaki run` does with the bundled example (examples/fox/shot.toml: three layers over a
// scanned paper) at a chosen size: a studio render's albedo from ACEScg (the 24-channel passes,
// as shot/inputs.cpp converts them), compositing.space = "scene_linear" (composite_frame's
// extra time over the display-referred composite: its layers' covered pixels and, once per
// shot, the paper) and the composite PNG through the Filmic view (file_store.cpp's
// to_display). Printed beside a temporal frame's time (shot_bench's figure for the size, given
// as SECONDS) as a share.
//
//   colour_bench [WIDTHxHEIGHT=960x540] [SECONDS=0] [REPEATS=10]
//
// Frame 0's layers are synthesized first (not timed). Each step's best wall time and best
// CPU time (all threads) over REPEATS runs; the share uses the wall time, as shot_bench does.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "colour/colour.h"
#include "composite/composite.h"
#include "core/parallel.h"
#include "core/performance.h"
#include "memory_store.h"
#include "pipeline/frames.h"
#include "pipeline/run.h"
#include "render/passes.h"
#include "shot/api.h"
#include "shot/inputs.h"

namespace {

using namespace emaki;

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Best {
  double wall = 1e30, cpu = 1e30;
};

// `prepare` (not timed) then `run`, `repeats` times: the best of each clock.
Best best_of(int repeats, const std::function<void()>& prepare, const std::function<void()>& run) {
  Best b;
  for (int i = 0; i < repeats; ++i) {
    prepare();
    const double c0 = cpu_seconds();
    const auto t0 = std::chrono::steady_clock::now();
    run();
    b.wall = std::min(b.wall,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    b.cpu = std::min(b.cpu, cpu_seconds() - c0);
  }
  return b;
}

// What each layer covers: what compositing converts (composite/composite.h).
void print_coverage(const pipeline::Shot& shot, ImageView<const float> passes,
                    const std::vector<ImageView<const float>>& layers) {
  const Image<float> albedo = pipeline::extract(passes, render::kAlbedo, 3);
  for (std::size_t i = 0; i < layers.size(); ++i) {
    composite::LayerInput in;
    in.value = layers[i];
    in.value_channels = shot.layers[i].single_colour ? 1 : 3;
    in.look = shot.layers[i].look;
    in.albedo = albedo.cview();
    const Image<float> rgba = composite::color_layer(in, passes.width, passes.height);
    long covered = 0;
    for (int y = 0; y < passes.height; ++y)
      for (int x = 0; x < passes.width; ++x) covered += rgba(x, y, 3) > 0.0f ? 1 : 0;
    std::printf("  layer %s covers %.1f %% of the frame\n", shot.layers[i].name.c_str(),
                100.0 * double(covered) / (double(passes.width) * passes.height));
  }
}

// composite_frame's time in scene_linear beyond its time in the display space, the two run in
// turn; the paper is made by the first call of each (once per shot), not counted. `comp`: the
// scene-linear composite.
Best compositing_extra(const pipeline::Shot& shot, ImageView<const float> passes,
                       const std::vector<ImageView<const float>>& layers, int repeats,
                       Image<float>& comp) {
  pipeline::Shot linear = shot;
  linear.compositing.space = pipeline::CompositingSpace::kSceneLinear;
  const pipeline::CompositeInputs display_ci = shot::load_composite_inputs(shot);
  const pipeline::CompositeInputs linear_ci = shot::load_composite_inputs(linear);
  const Best once = best_of(
      1, [] {}, [&] { comp = pipeline::composite_frame(linear, passes, layers, linear_ci); });
  pipeline::composite_frame(shot, passes, layers, display_ci);
  Best d, l;
  for (int i = 0; i < repeats; ++i) {
    const Best a = best_of(
        1, [] {}, [&] { comp = pipeline::composite_frame(shot, passes, layers, display_ci); });
    const Best b = best_of(
        1, [] {}, [&] { comp = pipeline::composite_frame(linear, passes, layers, linear_ci); });
    d = {std::min(d.wall, a.wall), std::min(d.cpu, a.cpu)};
    l = {std::min(l.wall, b.wall), std::min(l.cpu, b.cpu)};
  }
  std::printf("  (composite_frame: display %.2f ms, scene_linear %.2f ms; the first %.2f ms)\n",
              d.wall * 1e3, l.wall * 1e3, once.wall * 1e3);
  return {std::max(0.0, l.wall - d.wall), std::max(0.0, l.cpu - d.cpu)};
}

}  // namespace

int main(int argc, char** argv) {
  emaki::set_performance(emaki::performance_from_environment());  // as `emaki` does
  int width = 960, height = 540, repeats = 10;
  double frame_seconds = 0;
  if (argc > 1 && std::sscanf(argv[1], "%dx%d", &width, &height) != 2) {
    std::fprintf(stderr, "usage: colour_bench [WIDTHxHEIGHT] [SECONDS] [REPEATS]\n");
    return 2;
  }
  if (argc > 2) frame_seconds = std::atof(argv[2]);
  if (argc > 3) repeats = std::max(1, std::atoi(argv[3]));
  const ScopedThreadCount threads(0);
  try {
    pipeline::Shot shot = shot::open(std::string(EMAKI_SOURCE_DIR) + "/examples/fox/shot.toml");
    shot.source.width = shot.source.render.width = width;
    shot.source.height = shot.source.render.height = height;
    shot.source.last_frame = shot.source.first_frame;
    shot.source.shot.last_frame = shot.source.last_frame;
    const int frame = shot.source.first_frame;
    const auto source = shot::open_frames(shot);
    const auto exemplars = shot::load_exemplars(shot);
    bench::MemoryStore store;
    pipeline::RunOptions o;
    pipeline::run_shot(shot, *source, exemplars, pipeline::CompositeInputs{}, store, o);
    const Image<float> passes = source->passes(frame);
    std::vector<Image<float>> values;
    std::vector<ImageView<const float>> layers;
    for (const pipeline::Layer& l : shot.layers) values.push_back(store.read_layer(l, frame));
    for (const Image<float>& v : values) layers.push_back(v.cview());
    print_coverage(shot, passes.cview(), layers);
    const colour::Config& config = shot.colour.get();

    std::printf("colour management at %dx%d, examples/fox frame %d (best of %d; wall / CPU):\n",
                width, height, frame, repeats);
    double total = 0;
    auto report = [&](const char* name, Best b) {
      std::printf("  %-58s %7.2f ms / %7.2f ms\n", name, b.wall * 1e3, b.cpu * 1e3);
      total += b.wall;
    };
    Image<float> p;
    report("passes: albedo ACEScg -> scene_linear", best_of(
                                                        repeats, [&] { p = passes.clone(); },
                                                        [&] {
                                                          ImageView<float> albedo = p.view();
                                                          albedo.data += render::kAlbedo;
                                                          config.convert(albedo, colour::kAcescg,
                                                                         "scene_linear");
                                                        }));
    Image<float> comp;
    report("compositing.space = scene_linear: composite_frame's extra",
           compositing_extra(shot, passes.cview(), layers, repeats, comp));
    Image<float> rgb;
    report("composite PNG: scene_linear -> sRGB / Filmic",
           best_of(
               repeats,
               [&] {
                 rgb = Image<float>(width, height, 3);
                 for (int y = 0; y < height; ++y)
                   for (int x = 0; x < width; ++x)
                     for (int c = 0; c < 3; ++c) rgb(x, y, c) = comp(x, y, c);
               },
               [&] { config.to_display(rgb.view(), "scene_linear", "sRGB", "Filmic"); }));
    std::printf("per frame: %.2f ms", total * 1e3);
    if (frame_seconds > 0)
      std::printf(", %.2f %% of a %.2f s temporal frame", 100.0 * total / frame_seconds,
                  frame_seconds);
    std::printf(" (%d threads)\n", thread_count());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "colour_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
