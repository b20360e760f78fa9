#include "core/performance.h"

#include <sys/mman.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "core/image.h"

namespace emaki {

namespace {
std::atomic<bool> g_simd{true};
}  // namespace

namespace detail {
void advise_huge_pages(void* p, std::size_t bytes) {
  if (bytes < kHugePageAdviceBytes) return;
  constexpr std::uintptr_t kPage = 4096;  // the advice covers whole pages inside the block
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + kPage - 1) / kPage * kPage;
  const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) / kPage * kPage;
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}
}  // namespace detail

Performance performance() {
  Performance p;
  p.huge_page_advice = detail::image_block_hook.load() == &detail::advise_huge_pages;
  p.simd = g_simd.load();
  return p;
}

void set_performance(const Performance& p) {
  detail::image_block_hook.store(p.huge_page_advice ? &detail::advise_huge_pages : nullptr);
  g_simd.store(p.simd);
}

Performance performance_from_environment() {
  Performance p;
  p.huge_page_advice = true;
  const char* simd = std::getenv("EMAKI_SIMD");
  p.simd = !(simd && std::strcmp(simd, "scalar") == 0);
  return p;
}

}  // namespace emaki
