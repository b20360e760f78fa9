// Image storage: large images ask for transparent huge pages before their first touch.
#include "core/image.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

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
  const Image<float> large(1024, 1024, 4);  // 16 MB
  EXPECT_NE(vm_flags_at(large.row(512)).find(" hg"), std::string::npos)
      << vm_flags_at(large.row(512));
  EXPECT_EQ(large(100, 700, 3), 0.0f);  // still zero-filled
}

TEST(Image, AdviceOnABlockWithoutAWholePageDoesNothing) {
  // Below the threshold nothing is advised; inside a block of the threshold's size that starts
  // off a page boundary, only the whole pages are (no error either way: it is advice).
  float small[16] = {};
  detail::advise_huge_pages(small, sizeof(small));
  std::vector<char> block(detail::kHugePageAdviceBytes + 1);
  detail::advise_huge_pages(block.data() + 1, detail::kHugePageAdviceBytes);
  EXPECT_EQ(small[3], 0.0f);
  EXPECT_EQ(block[7], 0);
}

}  // namespace
}  // namespace emaki
