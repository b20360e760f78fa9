// Parallel loops. Work is cut into chunks whose boundaries depend only on the problem size
// (never on the thread count), so any per-chunk state gives the same result for 1 or N threads.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

namespace emaki {

// The number of threads parallel_for calls made on this thread may use.
int thread_count();

// While it lives, parallel_for calls made on the constructing thread use at most `n` threads
// (0: the enclosing ScopedThreadCount's count, else all hardware threads). Each one has its own
// task arena and nothing process-wide is ever reset, so callers on different threads (Python
// threads, two shots run at once, each with its own thread count) never disturb one another.
class ScopedThreadCount {
 public:
  explicit ScopedThreadCount(int n);
  ~ScopedThreadCount();
  ScopedThreadCount(const ScopedThreadCount&) = delete;
  ScopedThreadCount& operator=(const ScopedThreadCount&) = delete;

  struct Arena;

 private:
  std::unique_ptr<Arena> arena_;
  Arena* previous_ = nullptr;
};

// Calls fn(begin, end) over [0, n) in chunks of `grain` items, in parallel. The calling thread's
// pixel budget (core/limits.h) holds inside fn on every worker thread.
void parallel_for(int64_t n, int64_t grain, const std::function<void(int64_t, int64_t)>& fn);

// Calls fn() so that the parallel work it starts never has this thread run other tasks of the
// loops around it meanwhile (TBB lets a waiting thread take any pending task): for a loop body
// that holds per-thread scratch across a call that may itself run parallel work.
void isolated(const std::function<void()>& fn);

// Calls fn(y0, y1) over row bands of `band` rows.
inline void parallel_rows(int height, int band, const std::function<void(int, int)>& fn) {
  parallel_for(height, band, [&](int64_t a, int64_t b) { fn(int(a), int(b)); });
}

}  // namespace emaki
