// When emaki starts itself again with huge pages, and with what tunables.
#include "apps/emaki/huge_pages.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace emaki::app
