// emaki lookdev's loop: watch a few files (polling their modification time, size and inode, so
// an editor's save-by-rename counts), and run the work on a save: at once for a save after a
// quiet time, else once the saves have settled. A save that comes while the work runs marks that
// run stale (the work polls `stale` and stops early); the next run starts when the saves settle
// again. A burst of saves therefore costs at most the run its first save started and one more.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace emaki::view {

struct RerunOptions {
  std::chrono::milliseconds poll{25};     // how often the files are looked at
  std::chrono::milliseconds settle{150};  // quiet time after the last save before a run
};

class Rerun {
 public:
  // `work(stale)` runs on a thread of this object, once at start() and then after each settled
  // burst of saves; it should return soon after `stale` turns true.
  Rerun(std::vector<std::filesystem::path> files,
        std::function<void(const std::atomic<bool>& stale)> work, RerunOptions options = {});
  ~Rerun();
  Rerun(const Rerun&) = delete;
  Rerun& operator=(const Rerun&) = delete;

  void start();
  void stop();

  int runs_started() const { return m_started.load(); }
  int runs_finished() const { return m_finished.load(); }
  // Saves seen (changes of the files' stamps between two polls).
  int saves_seen() const { return m_saves.load(); }

 private:
  std::string stamps() const;
  void watch(std::string seen);
  void run_loop();

  std::vector<std::filesystem::path> m_files;
  std::function<void(const std::atomic<bool>&)> m_work;
  RerunOptions m_options;
  std::mutex m_mutex;
  std::condition_variable m_wake;
  bool m_pending = true, m_stopping = false, m_leading = false;
  std::chrono::steady_clock::time_point m_last_save{};
  std::atomic<bool> m_stale{false}, m_running{false};
  std::atomic<int> m_started{0}, m_finished{0}, m_saves{0};
  std::thread m_watcher, m_runner;
};

}  // namespace emaki::view
