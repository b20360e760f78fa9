// The cost of colour management per frame, the most a shot can ask for: a studio render's
// albedo from ACEScg (the 24-channel passes), compositing.space = "scene_linear" (the paper
// and the bundled shot's three coloured layers to scene-linear) and the Filmic view on the
// composite PNG. Printed beside a temporal frame's time (shot_bench's figure for the size,
// given as SECONDS) as a share.
//
//   colour_bench [WIDTHxHEIGHT=960x540] [SECONDS=0] [REPEATS=10]
//
// Each conversion's best time over REPEATS runs (the pipeline does each once per frame).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "colour/colour.h"
#include "core/image.h"
#include "render/passes.h"

int main(int argc, char** argv) {
  using namespace emaki;
  int width = 960, height = 540, repeats = 10;
  double frame_seconds = 0;
  if (argc > 1 && std::sscanf(argv[1], "%dx%d", &width, &height) != 2) {
    std::fprintf(stderr, "usage: colour_bench [WIDTHxHEIGHT] [SECONDS] [REPEATS]\n");
    return 2;
  }
  if (argc > 2) frame_seconds = std::atof(argv[2]);
  if (argc > 3) repeats = std::max(1, std::atoi(argv[3]));
  const auto config = colour::Config::builtin();
  auto filled = [&](int channels) {
    Image<float> img(width, height, channels);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < channels; ++c)
          img(x, y, c) = float((x * 7 + y * 13 + c * 29) % 256) / 255.0f;
    return img;
  };
  Image<float> passes = filled(render::kChannelCount), rgba = filled(4), rgb = filled(3);
  ImageView<float> albedo = passes.view();
  albedo.data += render::kAlbedo;
  struct Step {
    const char* name;
    int per_frame;
    std::function<void()> run;
  };
  const std::vector<Step> steps = {
      {"passes: albedo ACEScg -> scene_linear", 1,
       [&] { config->convert(albedo, colour::kAcescg, "scene_linear"); }},
      {"layer or paper: color_picking -> scene_linear", 4,
       [&] { config->convert(rgba.view(), "color_picking", "scene_linear"); }},
      {"composite PNG: scene_linear -> sRGB / Filmic", 1,
       [&] { config->to_display(rgb.view(), "scene_linear", "sRGB", "Filmic"); }},
  };
  double total = 0;
  std::printf("colour conversions at %dx%d (best of %d):\n", width, height, repeats);
  for (const Step& s : steps) {
    s.run();  // the processor is made once per shot: not timed
    double best = 1e30;
    for (int i = 0; i < repeats; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      s.run();
      best = std::min(best,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("  %-48s %7.2f ms x %d\n", s.name, best * 1e3, s.per_frame);
    total += best * s.per_frame;
  }
  std::printf("per frame: %.2f ms", total * 1e3);
  if (frame_seconds > 0)
    std::printf(", %.2f %% of a %.2f s temporal frame", 100.0 * total / frame_seconds,
                frame_seconds);
  std::printf("\n");
  return 0;
}
