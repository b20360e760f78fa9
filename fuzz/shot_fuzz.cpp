// Fuzz target `shot`: the shot-file parser (shot::parse_shot) on arbitrary bytes. Every input
// must end in a parsed shot or an emaki::Error; anything else escaping, a sanitizer report, a
// leak, > 2 GB or > 30 s is a bug.
//
// The shot "lives" in a private temporary folder holding empty stand-ins for the files the
// corpus names (scene.glb, painting.png, paper.png, passes.exr, frame_0000.exr), so inputs get
// past the existence checks into the rest of the schema. parse_shot only reads: the output
// folder is checked with access(), never created, so nothing is written outside that folder.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "core/error.h"
#include "core/limits.h"
#include "shot/parser.h"

namespace {

std::string make_home() {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("emaki_shot_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* name :
       {"scene.glb", "painting.png", "paper.png", "passes.exr", "frame_0000.exr"})
    std::ofstream(dir / name, std::ios::binary);
  return (dir / "shot.toml").string();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = [] {
    // Pinned: a file's limits.max_pixels must not change the budget for the inputs after it.
    emaki::set_max_pixels(emaki::kDefaultMaxPixels);
    return make_home();
  }();
  try {
    (void)emaki::shot::parse_shot(std::string_view(reinterpret_cast<const char*>(data), size),
                                  path);
  } catch (const emaki::Error&) {
  }
  return 0;
}
