// Why a path named as an input cannot be read as one. A device (/dev/zero), a FIFO or a socket
// exists but has no end or no size to check against: it is "not a regular file", never "no such
// file", which would send the user looking for a file that is there.
#pragma once

#include <filesystem>
#include <string>

namespace emaki::io {

// Empty when `path` is a regular file (or a symlink to one); else "no such file", "is a
// folder, not a file" or "is not a regular file (a device, FIFO or socket)".
inline std::string input_file_problem(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (std::filesystem::is_regular_file(st)) return {};
  if (!std::filesystem::exists(st)) return "no such file";
  if (std::filesystem::is_directory(st)) return "is a folder, not a file";
  return "is not a regular file (a device, FIFO or socket)";
}

// The same as a phrase naming the file (`shown`, already echoed): "no such file 'x'" or
// "'x' is not a regular file (...)"; empty for a regular file.
inline std::string input_file_problem(const std::string& path, const std::string& shown) {
  const std::string p = input_file_problem(path);
  if (p.empty()) return p;
  return p == "no such file" ? p + " '" + shown + "'" : "'" + shown + "' " + p;
}

}  // namespace emaki::io
