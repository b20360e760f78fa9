// How emaki uses the machine: settings that change speed and how memory is mapped, never a
// result. The engine and the image type follow them; only the front ends set them (apps/emaki,
// the Python module and the benchmarks, first thing), from the one switch they document: the
// environment, read by performance_from_environment() (docs/developing.md, "Environment").
// Without a front end (the tests, a program linking the libraries) the defaults below hold.
#pragma once

#include <cstddef>

namespace emaki {

struct Performance {
  // Every image of kHugePageAdviceBytes or more asks the kernel for transparent huge pages
  // before its first touch (madvise MADV_HUGEPAGE): where the kernel's THP mode is "madvise" it
  // is then faulted in 2 MB at a time instead of 4 KB. The Python module's and Blender's only
  // way to huge pages; `emaki` also restarts itself with glibc's tunable (apps/emaki/
  // huge_pages.h; docs/design/huge-pages.md).
  bool huge_page_advice = false;
  // The AVX2 patch-distance kernels where the CPU has them; false: the scalar ones (the same
  // results, bit for bit).
  bool simd = true;
};

// The process's settings.
Performance performance();
// Call before any work starts (images already allocated keep their mapping).
void set_performance(const Performance& p);
// What the front ends apply: huge-page advice on; the SIMD kernels unless EMAKI_SIMD=scalar.
Performance performance_from_environment();

namespace detail {
inline constexpr std::size_t kHugePageAdviceBytes = std::size_t(4) << 20;
// The advice on the whole pages inside [p, p + bytes), for a block of kHugePageAdviceBytes or
// more (smaller ones are left alone). Advice only: a kernel without transparent huge pages
// refuses it, and nothing changes then.
void advise_huge_pages(void* p, std::size_t bytes);
}  // namespace detail

}  // namespace emaki
