// Image storage: large images ask for transparent huge pages before their first touch.
#include "core/image.h"

#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "core/performance.h"

namespace emaki {
namespace {

std::string slurp(const char* path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The VmFlags line of the mapping of /proc/self/smaps that holds `p`.
std::string vm_flags_at(const void* p) {
  std::istringstream smaps(slurp("/proc/self/smaps"));
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
      inside = lo <= a && a < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return {};
}

TEST(Image, LargeImagesAskForHugePagesWhereTheKernelTakesAdvice) {
  if (slurp("/sys/kernel/mm/transparent_hugepage/enabled").find("[madvise]") == std::string::npos)
    GTEST_SKIP() << "the kernel's THP mode is not madvise";
  const Performance before = performance();
  Performance advice = before;
  advice.huge_page_advice = true;  // as the front ends set it
  set_performance(advice);
  const Image<float> large(1024, 1024, 4);  // 16 MB
  set_performance(before);
  EXPECT_NE(vm_flags_at(large.row(512)).find(" hg"), std::string::npos)
      << vm_flags_at(large.row(512));
  EXPECT_EQ(large(100, 700, 3), 0.0f);  // still zero-filled
}

// Without a front end's setting, an image is plain memory: no advice.
TEST(Image, NoAdviceUnlessAFrontEndAsksForIt) {
  ASSERT_FALSE(performance().huge_page_advice);
  EXPECT_EQ(detail::image_block_hook.load(), nullptr);
  const Performance env = performance_from_environment();
  EXPECT_TRUE(env.huge_page_advice);
}

TEST(Image, AdviceOnlyFromTheThresholdAndOnlyOnWholePages) {
  if (slurp("/sys/kernel/mm/transparent_hugepage/enabled").find("[madvise]") == std::string::npos)
    GTEST_SKIP() << "the kernel's THP mode is not madvise";
  // Two mappings of their own, so that no other advice in the process shows in their flags.
  const std::size_t n = 2 * detail::kHugePageAdviceBytes;
  char* below = static_cast<char*>(
      ::mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  char* from = static_cast<char*>(
      ::mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
  ASSERT_NE(below, MAP_FAILED);
  ASSERT_NE(from, MAP_FAILED);
  detail::advise_huge_pages(below, detail::kHugePageAdviceBytes - 1);
  EXPECT_EQ(vm_flags_at(below).find(" hg"), std::string::npos) << vm_flags_at(below);
  // A block off a page boundary: its first partial page keeps its flags, the whole pages after
  // it are advised.
  detail::advise_huge_pages(from + 1, detail::kHugePageAdviceBytes);
  EXPECT_EQ(vm_flags_at(from).find(" hg"), std::string::npos) << vm_flags_at(from);
  EXPECT_NE(vm_flags_at(from + 4096).find(" hg"), std::string::npos) << vm_flags_at(from + 4096);
  ::munmap(below, n);
  ::munmap(from, n);
}

}  // namespace
}  // namespace emaki
