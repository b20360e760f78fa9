#include "shot/memory.h"

#include <fmt/format.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "core/error.h"

namespace emaki::shot {

int64_t available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string key;
    int64_t kb = 0;
    if (fields >> key >> kb && key == "MemAvailable:" && kb > 0) return kb * 1024;
  }
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? int64_t(pages) * page : INT64_MAX;
}

std::string memory_text(int64_t bytes) {
  constexpr double kMb = 1024.0 * 1024.0, kGb = kMb * 1024.0;
  if (double(bytes) >= kGb) return fmt::format("{:.1f} GB", double(bytes) / kGb);
  return fmt::format("{} MB", int64_t(double(bytes) / kMb + 0.5));
}

void check_memory(int64_t bytes, int64_t max_bytes, const std::string& subject,
                  const std::string& what) {
  if (max_bytes > 0 && bytes > max_bytes)
    throw Error(Error::Field{"max_memory"},
                fmt::format("{} needs about {} of memory at its peak, more than the {} allowed",
                            what, memory_text(bytes), memory_text(max_bytes)));
  const int64_t available = available_memory_bytes();
  if (bytes > available)
    throw Error(subject, fmt::format("{} needs about {} of memory at its peak, more than the {} "
                                     "this machine has available",
                                     what, memory_text(bytes), memory_text(available)));
}

}  // namespace emaki::shot
