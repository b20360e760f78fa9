// When emaki starts itself again with huge pages, and with what tunables.
#include "apps/emaki/huge_pages.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>

namespace emaki::app {
namespace {

constexpr const char* kMadvise = "always [madvise] never\n";

TEST(HugePages, AddsTheTunableOnlyWhenTheKernelAsksForAdvice) {
  EXPECT_EQ(huge_page_tunables(nullptr, nullptr, kMadvise), "glibc.malloc.hugetlb=1");
  EXPECT_EQ(huge_page_tunables("", nullptr, kMadvise), "glibc.malloc.hugetlb=1");
  // "always" gives large mappings huge pages without advice; "never" gives none; no file, no mode.
  EXPECT_EQ(huge_page_tunables(nullptr, nullptr, "[always] madvise never\n"), std::nullopt);
  EXPECT_EQ(huge_page_tunables(nullptr, nullptr, "always madvise [never]\n"), std::nullopt);
  EXPECT_EQ(huge_page_tunables(nullptr, nullptr, ""), std::nullopt);
}

TEST(HugePages, KeepsTheUsersTunablesAndTheirChoice) {
  EXPECT_EQ(huge_page_tunables("glibc.malloc.arena_max=2", nullptr, kMadvise),
            "glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1");
  // Named already: the user's choice (=0 turns huge pages off), or our own restart.
  EXPECT_EQ(huge_page_tunables("glibc.malloc.hugetlb=0", nullptr, kMadvise), std::nullopt);
  EXPECT_EQ(
      huge_page_tunables("glibc.malloc.arena_max=2:glibc.malloc.hugetlb=1", nullptr, kMadvise),
      std::nullopt);
}

TEST(HugePages, OnlyTheCommandsThatMakeShotsFramesRestart) {
  for (const char* c : {"run", "task", "render", "composite", "qa", "lookdev"})
    EXPECT_TRUE(restarts_for_huge_pages(c)) << c;
  // synth takes the advice on its large images itself; the others are quick.
  for (const char* c : {"synth", "template", "plan", "farm", "view", "version", "--version",
                        "--help", "", "runx", "ru"})
    EXPECT_FALSE(restarts_for_huge_pages(c)) << c;
  EXPECT_FALSE(restarts_for_huge_pages(nullptr));
}

TEST(HugePages, NeverUnderValgrind) {
  // Valgrind preloads its core; /proc/self/exe is then its launcher, which refuses to run.
  EXPECT_EQ(
      huge_page_tunables(nullptr, "/usr/libexec/valgrind/vgpreload_core-amd64-linux.so", kMadvise),
      std::nullopt);
  EXPECT_EQ(huge_page_tunables(nullptr, "/usr/lib/libsomething.so", kMadvise),
            "glibc.malloc.hugetlb=1");
}

TEST(HugePages, AFarmTaskKeepsItsFreedMemoryInTheHeap) {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  GTEST_SKIP() << "a sanitizer's allocator takes no glibc malloc settings";
#endif
  ASSERT_TRUE(keep_freed_memory());
  // A 64 MB block (a 1080p frame's passes hold more) comes from the heap, not a mapping of its
  // own, and freeing it hands nothing back: the next one reuses the same pages.
  constexpr std::size_t kBytes = std::size_t(64) << 20;
  const std::size_t mapped_before = mallinfo2().hblkhd;
  void* a = std::malloc(kBytes);
  ASSERT_NE(a, nullptr);
  std::memset(a, 1, kBytes);
  EXPECT_EQ(mallinfo2().hblkhd, mapped_before);
  const std::size_t heap = mallinfo2().arena;
  std::free(a);
  EXPECT_EQ(mallinfo2().arena, heap);
  void* b = std::malloc(kBytes);
  EXPECT_EQ(mallinfo2().arena, heap);
  std::free(b);
}

}  // namespace
}  // namespace emaki::app
