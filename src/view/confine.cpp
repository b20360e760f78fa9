#include "view/confine.h"

#include "core/utf8.h"

namespace emaki::view {

namespace fs = std::filesystem;

bool lies_within(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    // A trailing '/' of root reads as an empty last component.
    if (r->empty() && std::next(r) == root.end()) break;
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

namespace {

// The request's own text, before the file system is asked anything.
bool acceptable_text(std::string_view relative) {
  if (relative.empty() || relative.size() > kMaxRequestPath) return false;
  if (first_invalid_utf8(relative) != std::string_view::npos) return false;
  if (relative.front() == '/') return false;
  for (const char c : relative) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f || c == '\\') return false;
  }
  std::size_t start = 0;
  while (start <= relative.size()) {
    std::size_t end = relative.find('/', start);
    if (end == std::string_view::npos) end = relative.size();
    const std::string_view part = relative.substr(start, end - start);
    // Empty components ("a//b") are refused too: no file name the viewer links holds them.
    if (part.empty() || part.front() == '.') return false;
    start = end + 1;
  }
  return true;
}

}  // namespace

std::optional<fs::path> confined_file(const fs::path& root, std::string_view relative) {
  if (!acceptable_text(relative)) return std::nullopt;
  std::error_code ec;
  const fs::path real_root = fs::canonical(root, ec);
  if (ec) return std::nullopt;
  const fs::path real = fs::canonical(real_root / fs::path(relative), ec);
  if (ec || !lies_within(real, real_root) || real == real_root) return std::nullopt;
  if (!fs::is_regular_file(real, ec) || ec) return std::nullopt;
  return real;
}

}  // namespace emaki::view
