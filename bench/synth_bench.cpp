// Synthesis benchmark: wall time of the StyLit example (style + 4 colour guides at weight 0.5,
// default settings) at three sizes, printed per pixel so the scaling can be read off. A timed
// harness, not a test: run it on an otherwise idle machine and compare ratios within one run.
//
//   synth_bench [--repeat N] [--threads N] [--data DIR]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "core/performance.h"
#include "io/image_io.h"
#include "synth/pyramid.h"
#include "synth/synthesizer.h"

using namespace emaki;

int main(int argc, char** argv) {
  emaki::set_performance(emaki::performance_from_environment());  // as `emaki` does
  std::string dir = std::string(EMAKI_SOURCE_DIR) + "/examples/stylit";
  int repeat = 3, threads = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--repeat")
      repeat = std::max(1, std::atoi(argv[i + 1]));
    else if (a == "--threads")
      threads = std::atoi(argv[i + 1]);
    else if (a == "--data")
      dir = argv[i + 1];
  }
  const ScopedThreadCount count(threads);
  const char* names[] = {"fullgi", "dirdif", "dirspc", "indirb"};
  Image<float> style = io::read_image_float(dir + "/source_style.png");
  std::vector<Image<float>> src, tgt;
  for (const char* n : names) {
    src.push_back(io::read_image_float(dir + "/source_" + std::string(n) + ".png"));
    tgt.push_back(io::read_image_float(dir + "/target_" + std::string(n) + ".png"));
  }
  std::printf(
      "synth_bench: StyLit, 3 style channels + 4 RGB guides, default settings, %d threads, best of "
      "%d\n",
      thread_count(), repeat);
  std::printf("%10s %10s %12s %14s\n", "size", "pixels", "seconds", "ns/pixel");
  std::vector<double> per_pixel;
  // Smallest first: 1/4, 1/2, full size, each halving low-passed.
  std::vector<std::pair<Image<float>, std::vector<std::pair<Image<float>, Image<float>>>>> sizes;
  for (int scale = 2; scale >= 0; --scale) {
    Image<float> s = style.clone();
    std::vector<std::pair<Image<float>, Image<float>>> g;
    for (std::size_t k = 0; k < src.size(); ++k) g.emplace_back(src[k].clone(), tgt[k].clone());
    for (int i = 0; i < scale; ++i) {
      s = synth::downsample(s.cview());
      for (auto& [a, b] : g) a = synth::downsample(a.cview()), b = synth::downsample(b.cview());
    }
    synth::Inputs in;
    in.style = s.cview();
    for (std::size_t k = 0; k < g.size(); ++k)
      in.guides.push_back({names[k], g[k].first.cview(), g[k].second.cview(), 0.5f});
    double best = 1e30;
    for (int r = 0; r < repeat; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      synth::Result res = synth::synthesize(in, synth::Params());
      const double sec =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      best = std::min(best, sec);
    }
    const double px = double(g[0].second.width()) * g[0].second.height();
    per_pixel.push_back(best / px * 1e9);
    char size[32];
    std::snprintf(size, sizeof size, "%dx%d", g[0].second.width(), g[0].second.height());
    std::printf("%10s %10.0f %12.3f %14.1f\n", size, px, best, per_pixel.back());
  }
  const double lo = *std::min_element(per_pixel.begin(), per_pixel.end());
  const double hi = *std::max_element(per_pixel.begin(), per_pixel.end());
  const double mid = (lo + hi) / 2;
  std::printf("per-pixel time spread: +-%.1f %% around %.1f ns\n", (hi - lo) / 2 / mid * 100, mid);
  return 0;
}
