// emaki: parse -> load -> pipeline -> report. Only this layer decides exit codes.

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "apps/emaki/commands.h"
#include "apps/emaki/huge_pages.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/performance.h"
#include "core/version.h"

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
      {"qa", "quality checks: 'emaki qa flicker|ghost SHOT --layer NAME'", run_qa},
      {"plan", "shots as a task graph for a render farm (a table, or --json)", run_plan},
      {"farm", "run shots on Slurm: 'emaki farm submit|status|cancel SHOT...'", run_farm},
      {"task", "one task of a plan, as a farm node runs it", run_task},
      {"view", "a local page of output folders: player, layers, A/B wipe, manifests", run_view},
      {"lookdev", "a few preview frames made again on every save of the painting, on a page",
       run_lookdev},
      {"version", "the version: the release, and the git revision when built from a checkout",
       run_version},
  };
  return list;
}

int run_version(const Args& args) {
  if (!args.empty() && args[0] != "--help" && args[0] != "-h")
    throw Error("", "usage: emaki version (or emaki --version)");
  std::printf("emaki %s\n", emaki::version());
  return 0;
}

namespace {

// The command line's spelling of each neutral field (Error::Field) an error from below apps/ can
// name: the one place a field becomes an option. A field missing here keeps its neutral name,
// which is true if not the option's spelling.
struct FieldOption {
  const char* field;
  const char* option;
};
constexpr FieldOption kFieldOptions[] = {
    {"frames", "--frames"}, {"fps", "--fps"},
    {"clip", "--clip"},     {"start", "--start"},
    {"aa", "--aa"},         {"gltf_node", "--gltf-camera"},
    {"sphere", "--sphere"}, {"horizon", "--horizon"},
    {"layers", "--layers"}, {"layer", "--layer"},
    {"chunk", "--chunk"},   {"threads", "--threads"},
    {"shots", "SHOT"},      {"max_memory", "--max-memory"},
    {"port", "--port"},
};

// An emaki::Error naming a field is re-spelled as its option; anything else reads as it is.
std::string error_text(const std::exception& e) {
  if (const auto* error = dynamic_cast<const emaki::Error*>(&e))
    for (const FieldOption& f : kFieldOptions)
      if (error->field() == f.field) return error->respelled(f.option).what();
  return e.what();
}

void print_usage() {
  std::printf("emaki — stylize 3D animation by example\n\nusage: emaki <command> [options]\n\n");
  for (const auto& c : commands()) std::printf("  %-10s %s\n", c.name, c.summary);
  std::printf(
      "\n'emaki <command> --help' documents a command's options. Every command also takes\n"
      "--max-pixels N: the largest image, in pixels, read or made (default 2^28).\n"
      "'emaki --version' prints the version.\n");
}
}  // namespace
}  // namespace emaki::app

int main(int argc, char** argv) {
  using namespace emaki::app;
  // Large buffers on huge pages where the kernel takes advice, for the commands that make shots'
  // frames (huge_pages.h, docs/design/huge-pages.md).
  restart_with_huge_pages(argv, argc > 1 ? argv[1] : nullptr);
  // The one performance switch (core/performance.h): huge-page advice on large images, SIMD
  // kernels unless EMAKI_SIMD=scalar.
  emaki::set_performance(emaki::performance_from_environment());
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    print_usage();
    return argc < 2 ? 2 : 0;
  }
  if (std::string(argv[1]) == "--version") return run_version({});
  const std::string name = argv[1];
  // `--max-pixels N` is global: the pixel budget every image read or allocated is checked
  // against before allocation (default 2^28). It may stand anywhere after the command.
  Args args;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a != "--max-pixels") {
      args.push_back(a);
      continue;
    }
    char* end = nullptr;
    const char* v = i + 1 < argc ? argv[i + 1] : "";
    errno = 0;
    const long long n = std::strtoll(v, &end, 10);
    if (*v == '\0' || *end != '\0' || errno != 0 || n < 1) {
      std::fprintf(stderr, "emaki %s: error: --max-pixels: expected a positive integer, got '%s'\n",
                   name.c_str(), emaki::echo(v).c_str());
      return 1;
    }
    emaki::set_max_pixels(n);
    ++i;
  }
  for (const auto& c : commands()) {
    if (name != c.name) continue;
    try {
      return c.run(args);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "emaki %s: error: %s\n", c.name, error_text(e).c_str());
      return 1;
    }
  }
  std::fprintf(stderr, "emaki: error: unknown command '%s' (see 'emaki --help')\n",
               emaki::echo(name).c_str());
  return 2;
}
