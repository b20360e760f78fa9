// The one path a request may name, resolved and confined to a served folder. Every file the
// viewer (emaki view / lookdev) sends goes through confined_file(): a request path either
// resolves to a regular file inside the folder, or nothing is served.
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>

namespace emaki::view {

// Longest request path (after percent-decoding) taken; longer ones are refused before any
// file-system call. Output files are named LAYER/LAYER_NNNN.png: far below this.
inline constexpr std::size_t kMaxRequestPath = 1024;

// The real path of the regular file `relative` names under `root` (a folder, made canonical
// by the caller or here), or nothing when:
//   - `relative` is empty, longer than kMaxRequestPath, not UTF-8, or holds NUL, a backslash
//     or a control character;
//   - it is absolute (starts with '/'), or any of its components is '..' or starts with '.'
//     (a hidden file: the run's lock, NNF caches and manifests are not served as files);
//   - once every symlink is resolved, the file lies outside `root`, or is not a regular file.
// `relative` is already percent-decoded (the HTTP layer decodes once; a '%' left after that is a
// literal character of a file name, never decoded again).
std::optional<std::filesystem::path> confined_file(const std::filesystem::path& root,
                                                   std::string_view relative);

// True when `path` (made canonical) is `root` or lies below it.
bool lies_within(const std::filesystem::path& path, const std::filesystem::path& root);

}  // namespace emaki::view
