// Output files written on a background thread, so that encoding (EXR compression, PNG) and the
// disk overlap the next frame's synthesis instead of adding to it. One thread runs the jobs in
// the order they were given: the files appear in the same order as when written in place, which
// is what resuming relies on (a layer's frame on disk means every earlier job finished).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace emaki::io {

class BackgroundWriter {
 public:
  // At most `max_pending` jobs wait (each holds its images): submit() blocks beyond that.
  explicit BackgroundWriter(std::size_t max_pending = 4);
  // Waits for the jobs given so far; an error no call reported is dropped (call wait() first).
  ~BackgroundWriter();
  BackgroundWriter(const BackgroundWriter&) = delete;
  BackgroundWriter& operator=(const BackgroundWriter&) = delete;

  // Queues `job`, which writes the files `paths` (known as pending until it ran). Rethrows the
  // error of an earlier job first; after an error no further job runs.
  void submit(std::set<std::string> paths, std::function<void()> job);
  // True while a queued or running job is to write `path`.
  bool pending(const std::string& path) const;
  // Waits until every job ran; rethrows the first error of one (once).
  void wait();
  // Rethrows the first error of a job that ran, if any (once), without waiting.
  void check();

 private:
  struct Job {
    std::set<std::string> paths;
    std::function<void()> run;
  };
  void loop();

  std::size_t max_pending_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;  // the front one runs while `running_`
  bool running_ = false, stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace emaki::io
