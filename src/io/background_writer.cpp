#include "io/background_writer.h"

#include <utility>

namespace emaki::io {

BackgroundWriter::BackgroundWriter(std::size_t max_pending)
    : max_pending_(max_pending), thread_([this] { loop(); }) {}

BackgroundWriter::~BackgroundWriter() {
  {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return jobs_.empty(); });
    stop_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void BackgroundWriter::loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return stop_ || !jobs_.empty(); });
    if (jobs_.empty()) return;  // stop_ and nothing left
    running_ = true;
    std::function<void()> run = jobs_.front().run;
    lock.unlock();
    std::exception_ptr e;
    try {
      run();
    } catch (...) {
      e = std::current_exception();
    }
    lock.lock();
    running_ = false;
    jobs_.pop_front();
    if (e && !error_) {
      error_ = e;
      jobs_.clear();  // after a failed write the later ones would leave a gap in the order
    }
    changed_.notify_all();
  }
}

void BackgroundWriter::submit(std::set<std::string> paths, std::function<void()> job) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return jobs_.size() < max_pending_ || error_; });
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  jobs_.push_back({std::move(paths), std::move(job)});
  changed_.notify_all();
}

bool BackgroundWriter::pending(const std::string& path) const {
  std::lock_guard lock(mutex_);
  for (const Job& j : jobs_)
    if (j.paths.count(path)) return true;
  return false;
}

void BackgroundWriter::wait() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return jobs_.empty(); });
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void BackgroundWriter::check() {
  std::lock_guard lock(mutex_);
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

}  // namespace emaki::io
