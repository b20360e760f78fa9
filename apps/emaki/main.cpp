// emaki: parse -> load -> pipeline -> report. Only this layer decides exit codes.
#include <malloc.h>

#include <cstdio>
#include <exception>
#include <string>

#include "apps/emaki/commands.h"
#include "core/error.h"

namespace emaki::app {

const std::vector<Command>& commands() {
  static const std::vector<Command> list = {
      {"synth", "guided patch-based synthesis (EbSynth-compatible command line)", run_synth},
      {"render", "guide passes of a glTF scene, one multilayer EXR per frame", run_render},
      {"template", "reference sphere passes and a paint template (or fit them to a painting)",
       run_template},
      {"run", "a whole shot from its shot file: layers, temporal chain, compositing, previews",
       run_run},
      {"composite", "re-colour a shot's finished layers without synthesizing again", run_composite},
      {"qa", "quality checks: 'emaki qa flicker SHOT --layer NAME'", run_qa},
  };
  return list;
}

namespace {
void print_usage() {
  std::printf("emaki — stylize 3D animation by example\n\nusage: emaki <command> [options]\n\n");
  for (const auto& c : commands()) std::printf("  %-10s %s\n", c.name, c.summary);
  std::printf("\n'emaki <command> --help' documents a command's options.\n");
}
}  // namespace
}  // namespace emaki::app

int main(int argc, char** argv) {
  using namespace emaki::app;
  // Large image buffers come and go level by level; a fixed mmap threshold hands them back to
  // the system when freed instead of leaving them in a fragmented heap (peak RSS).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    print_usage();
    return argc < 2 ? 2 : 0;
  }
  const std::string name = argv[1];
  Args args(argv + 2, argv + argc);
  for (const auto& c : commands()) {
    if (name != c.name) continue;
    try {
      return c.run(args);
    } catch (const emaki::Error& e) {
      std::fprintf(stderr, "emaki %s: error: %s\n", c.name, e.what());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "emaki %s: error: %s\n", c.name, e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "emaki: error: unknown command '%s' (see 'emaki --help')\n", name.c_str());
  return 2;
}
