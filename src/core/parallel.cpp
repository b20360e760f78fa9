#include "core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

#include "core/limits.h"

namespace emaki {
namespace {
// This thread's ScopedThreadCount, if any.
thread_local ScopedThreadCount::Arena* t_arena = nullptr;
}  // namespace

struct ScopedThreadCount::Arena {
  tbb::task_arena arena;
  explicit Arena(int n) : arena(n) {}
};

namespace {

// Without this, TBB sizes its worker pool by the first arena it sees: a first run with one
// thread would cap every later run at one. Allowing plenty lets each arena get what it asks.
void allow_parallelism() {
  static tbb::global_control allow(
      tbb::global_control::max_allowed_parallelism,
      std::max<std::size_t>(64, tbb::this_task_arena::max_concurrency()));
}

// The arena of calls outside any ScopedThreadCount: all hardware threads. Made once and never
// reset, so no thread can find the arena it runs in destroyed under it.
tbb::task_arena& default_arena() {
  static tbb::task_arena* const a = [] {
    allow_parallelism();
    return new tbb::task_arena(tbb::this_task_arena::max_concurrency());
  }();
  return *a;
}

tbb::task_arena& arena() {
  return t_arena ? t_arena->arena : default_arena();
}

// Runs a chunk, on whichever thread, under the settings of the thread that called parallel_for:
// its arena (a nested parallel_for keeps the caller's thread count) and its pixel budget.
struct CallersChunk {
  const std::function<void(int64_t, int64_t)>& fn;
  ScopedThreadCount::Arena* arena;
  int64_t budget;
  void operator()(int64_t a, int64_t b) const {
    ScopedThreadCount::Arena* const previous = std::exchange(t_arena, arena);
    const ScopedMaxPixels scope(budget);
    try {
      fn(a, b);
    } catch (...) {
      t_arena = previous;
      throw;
    }
    t_arena = previous;
  }
};
}  // namespace

ScopedThreadCount::ScopedThreadCount(int n) : previous_(t_arena) {
  if (n <= 0) return;
  allow_parallelism();  // before the first arena is made
  arena_ = std::make_unique<Arena>(n);
  t_arena = arena_.get();
}

ScopedThreadCount::~ScopedThreadCount() {
  t_arena = previous_;
}

int thread_count() {
  return arena().max_concurrency();
}

void parallel_for(int64_t n, int64_t grain, const std::function<void(int64_t, int64_t)>& body) {
  if (n <= 0) return;
  const CallersChunk fn{body, t_arena, scoped_max_pixels()};
  grain = std::max<int64_t>(1, grain);
  const int64_t chunks = (n + grain - 1) / grain;
  if (chunks == 1) {
    fn(0, n);
    return;
  }
#if defined(__SANITIZE_THREAD__)
  // Debian's libtbb is not built with ThreadSanitizer, which then cannot see the ordering TBB's
  // joins give and reports races everywhere. Under TSan, plain threads (whose create and join
  // it understands) pull the same chunks, so TSan checks emaki's own code.
  std::atomic<int64_t> next{0};
  std::mutex failed_mutex;
  std::exception_ptr failed;
  auto worker = [&] {
    try {
      for (int64_t c; (c = next.fetch_add(1)) < chunks;)
        fn(c * grain, std::min(n, (c + 1) * grain));
    } catch (...) {
      std::lock_guard lock(failed_mutex);
      if (!failed) failed = std::current_exception();
      next = chunks;
    }
  };
  std::vector<std::thread> threads;
  const int64_t extra = std::min<int64_t>(chunks, thread_count()) - 1;
  for (int64_t t = 0; t < extra; ++t) threads.emplace_back(worker);
  worker();
  for (auto& t : threads) t.join();
  if (failed) std::rethrow_exception(failed);
  return;
#endif
  arena().execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int64_t>(0, chunks, 1),
        [&](const tbb::blocked_range<int64_t>& r) {
          for (int64_t c = r.begin(); c != r.end(); ++c)
            fn(c * grain, std::min(n, (c + 1) * grain));
        },
        tbb::simple_partitioner());
  });
}

void isolated(const std::function<void()>& fn) {
#if defined(__SANITIZE_THREAD__)
  fn();  // parallel_for runs plain threads there: a waiting thread takes no other task
#else
  tbb::this_task_arena::isolate([&] { fn(); });
#endif
}

}  // namespace emaki
