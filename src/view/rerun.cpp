#include "view/rerun.h"

#include <sys/stat.h>

namespace emaki::view {

namespace fs = std::filesystem;

Rerun::Rerun(std::vector<fs::path> files, std::function<void(const std::atomic<bool>&)> work,
             RerunOptions options)
    : m_files(std::move(files)), m_work(std::move(work)), m_options(options) {}

Rerun::~Rerun() {
  stop();
}

void Rerun::start() {
  // The stamps the first save is compared against are taken here, before the first run starts:
  // taken on the watcher's thread, a save made once the run has started could become the
  // reference itself and never be seen.
  m_watcher = std::thread([this, seen = stamps()]() mutable { watch(std::move(seen)); });
  m_runner = std::thread([this] { run_loop(); });
}

void Rerun::stop() {
  {
    std::lock_guard lock(m_mutex);
    m_stopping = true;
  }
  m_stale = true;
  m_wake.notify_all();
  if (m_watcher.joinable()) m_watcher.join();
  if (m_runner.joinable()) m_runner.join();
}

// Modification time (ns), size and inode of each file; a missing file reads as zeros (an editor
// between its delete and its rename).
std::string Rerun::stamps() const {
  std::string s;
  for (const fs::path& f : m_files) {
    struct stat st {};
    if (::stat(f.c_str(), &st) != 0) st = {};
    s += std::to_string(st.st_mtim.tv_sec) + "." + std::to_string(st.st_mtim.tv_nsec) + ":" +
         std::to_string(st.st_size) + ":" + std::to_string(st.st_ino) + ";";
  }
  return s;
}

void Rerun::watch(std::string seen) {
  std::unique_lock lock(m_mutex);
  while (!m_stopping) {
    m_wake.wait_for(lock, m_options.poll, [&] { return m_stopping; });
    if (m_stopping) break;
    lock.unlock();
    std::string now = stamps();
    lock.lock();
    if (now == seen) continue;
    seen = std::move(now);
    ++m_saves;
    m_pending = true;
    const auto t = std::chrono::steady_clock::now();
    // A save after a quiet time, with no run going, starts a run at once (the first save of a
    // burst); a save within `settle` of the last one waits for the burst to end.
    m_leading = !m_running && t - m_last_save >= m_options.settle;
    m_last_save = t;
    if (m_running) m_stale = true;
    m_wake.notify_all();
  }
}

void Rerun::run_loop() {
  std::unique_lock lock(m_mutex);
  while (!m_stopping) {
    const auto due = m_last_save + m_options.settle;
    if (!m_pending) {
      m_wake.wait(lock);
      continue;
    }
    if (!m_leading && std::chrono::steady_clock::now() < due) {
      m_wake.wait_until(lock, due);
      continue;
    }
    m_pending = m_leading = false;
    m_stale = false;
    m_running = true;
    ++m_started;
    lock.unlock();
    m_work(m_stale);
    lock.lock();
    m_running = false;
    ++m_finished;
  }
}

}  // namespace emaki::view
