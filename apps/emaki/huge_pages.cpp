#include "apps/emaki/huge_pages.h"

#include <malloc.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

namespace emaki::app {

bool restarts_for_huge_pages(const char* command) {
  if (!command) return false;
  for (const char* c : {"run", "task", "render", "composite", "qa", "lookdev"})
    if (std::strcmp(command, c) == 0) return true;
  return false;
}

std::optional<std::string> huge_page_tunables(const char* tunables, const char* preload,
                                              const std::string& thp_mode) {
  if (thp_mode.find("[madvise]") == std::string::npos) return std::nullopt;
  if (preload && std::string(preload).find("vgpreload") != std::string::npos) return std::nullopt;
  const std::string current = tunables ? tunables : "";
  if (current.find("glibc.malloc.hugetlb") != std::string::npos) return std::nullopt;
  return current.empty() ? "glibc.malloc.hugetlb=1" : current + ":glibc.malloc.hugetlb=1";
}

void restart_with_huge_pages(char** argv, const char* command) {
  if (!restarts_for_huge_pages(command)) return;
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string mode((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const char* before = std::getenv("GLIBC_TUNABLES");
  const std::optional<std::string> tunables =
      huge_page_tunables(before, std::getenv("LD_PRELOAD"), mode);
  if (!tunables) return;
  const std::string kept = before ? before : "";
  if (::setenv("GLIBC_TUNABLES", tunables->c_str(), 1) != 0) return;
  ::execv("/proc/self/exe", argv);  // returns only on failure: go on as we were
  if (before)
    ::setenv("GLIBC_TUNABLES", kept.c_str(), 1);
  else
    ::unsetenv("GLIBC_TUNABLES");
}

bool keep_freed_memory() {
  constexpr int kMmapThreshold = 256 << 20, kTrimThreshold = 1 << 30;
  const bool mapped = ::mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1;
  return ::mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1 && mapped;
}

}  // namespace emaki::app
