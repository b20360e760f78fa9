// Fuzzes the viewer's path confinement (src/view/confine.h) over a fixed tree: an output folder
// with a frame, a hidden file, a symlink to a file outside and a symlink to the folder above,
// beside a secret file. Whatever the request path, a file served must be a regular file inside
// the folder (after resolving every symlink), never the secret; anything else is a bug.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string_view>

#include "view/confine.h"

namespace {

namespace fs = std::filesystem;

struct Tree {
  fs::path base, root;
  Tree() {
    base = fs::temp_directory_path() / ("emaki_confine_fuzz_" + std::to_string(::getpid()));
    root = base / "out";
    fs::remove_all(base);
    fs::create_directories(root / "composite");
    std::ofstream(root / "composite" / "frame_0000.png") << "png";
    std::ofstream(root / "composite" / ".emaki-manifest") << "manifest";
    std::ofstream(base / "secret") << "secret";
    fs::create_symlink(base / "secret", root / "composite" / "out.png");
    fs::create_directory_symlink(base, root / "up");
    root = fs::canonical(root);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static const Tree tree;
  const std::string_view path(reinterpret_cast<const char*>(data), size);
  const auto file = emaki::view::confined_file(tree.root, path);
  if (!file) return 0;
  if (!emaki::view::lies_within(*file, tree.root) || *file == fs::canonical(tree.base / "secret") ||
      !fs::is_regular_file(*file) || file->filename().string().front() == '.')
    std::abort();
  return 0;
}
