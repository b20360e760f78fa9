// Opens a shot file with emaki's shot API and asks the engine for its pyramid depth.
#include <cstdio>

#include "core/version.h"
#include "shot/api.h"
#include "synth/synthesizer.h"

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const emaki::pipeline::Shot shot = emaki::shot::open(argv[1]);
  std::printf("emaki %s: %zu layers, %d pyramid levels at 64x64\n", emaki::version(),
              shot.layers.size(), emaki::synth::max_pyramid_levels(64, 64, 64, 64, 5));
  return 0;
}
