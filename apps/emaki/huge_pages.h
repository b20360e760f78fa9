// Transparent huge pages for emaki's own process: glibc maps every large image anew and the
// kernel faults it in 4 KB at a time. On a kernel whose THP mode is "madvise", glibc's tunable
// glibc.malloc.hugetlb=1 has malloc advise huge pages on what it maps: 2 MB per fault instead of
// 4 KB (a 6-frame `emaki run` of the example: 0.56 M page faults -> 0.03 M, wall -20 to -35 %;
// docs/design/huge-pages.md). Tunables are read only when a program starts, so `emaki` starts
// itself again once with the tunable added, for the commands that make shots' frames: the restart
// loads every library again (about 20 ms of CPU), which `emaki synth` did not win back at any size
// measured (its images of 4 MB or more take the advice themselves, core/performance.h) and the
// quick commands never could. Outputs do not change: only where memory comes from.
#pragma once

#include <optional>
#include <string>

namespace emaki::app {

// Whether `command` (emaki's first argument, may be null) makes shots' frames: run, task, render,
// composite, qa, lookdev. Only those start again with huge pages.
bool restarts_for_huge_pages(const char* command);

// The GLIBC_TUNABLES value to start again with, or nullopt to go on as we are: when the kernel's
// THP mode (the text of /sys/kernel/mm/transparent_hugepage/enabled, "always [madvise] never")
// is not "madvise" (with "always" every large mapping gets huge pages already; with "never" none
// can), or when `tunables` (the current GLIBC_TUNABLES, may be null) already names
// glibc.malloc.hugetlb (the user's choice, =0 turns this off; also what ends the one restart),
// or when `preload` (LD_PRELOAD, may be null) shows Valgrind, whose launcher a restart through
// /proc/self/exe would run instead of emaki.
std::optional<std::string> huge_page_tunables(const char* tunables, const char* preload,
                                              const std::string& thp_mode);

// Starts this program again (same arguments, same pid) with the tunable added when `command`
// restarts (restarts_for_huge_pages) and huge_page_tunables says so; returns when it does not, or
// when the restart fails (nothing changes then). Call first thing in main, before any thread is
// started.
void restart_with_huge_pages(char** argv, const char* command);

// A farm task (`emaki task`) keeps the memory it frees for its next frames: glibc's mmap
// threshold at 256 MB (below it, blocks come from the heap instead of a mapping of their own)
// and its trim threshold at 1 GB (freed memory is not handed back to the kernel). Without it a
// task maps its frames' images afresh and the kernel zeroes every page again at its first touch:
// the production's tasks took 229,000 page faults where `emaki run` of the same shots took 55,000,
// and their system time was twice the run's. A task lives for one chunk of frames, so the memory
// it holds comes back at its exit; `emaki run`, which may hold a whole shot at 1080p, keeps
// glibc's own thresholds (the same setting raised its 1080p peak by 5 %). Returns whether glibc
// took both settings. Call before the task allocates its frames.
bool keep_freed_memory();

}  // namespace emaki::app
