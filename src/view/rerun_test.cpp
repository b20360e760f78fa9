// Rerun: saves coalesce into runs, a save during a run makes it stale, and a burst of ten saves
// costs at most two runs.
#include "view/rerun.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

namespace emaki::view {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

fs::path test_file(const char* name) {
  const fs::path p = fs::temp_directory_path() /
                     (std::string("emaki_rerun_") + name + "_" + std::to_string(::getpid()));
  std::ofstream(p) << "0";
  return p;
}

void save(const fs::path& p, int i) {
  const fs::path tmp = p.string() + ".tmp";
  std::ofstream(tmp) << "save " << i;
  fs::rename(tmp, p);  // as editors save: a new file renamed over the old one
}

void wait_for(const std::function<bool()>& done) {
  for (int i = 0; i < 1000 && !done(); ++i) std::this_thread::sleep_for(10ms);
}

TEST(Rerun, RunsOnceAtStart) {
  const fs::path f = test_file("start");
  std::atomic<int> runs{0};
  Rerun r({f}, [&](const std::atomic<bool>&) { ++runs; });
  r.start();
  wait_for([&] { return r.runs_finished() == 1; });
  std::this_thread::sleep_for(400ms);
  EXPECT_EQ(runs.load(), 1);
  r.stop();
  fs::remove(f);
}

TEST(Rerun, ABurstOfTenSavesRunsAtMostTwice) {
  const fs::path f = test_file("burst");
  std::atomic<int> frames_run{0};
  // The work: three "frames" of 60 ms each, stopping at the first frame boundary once stale.
  Rerun r({f}, [&](const std::atomic<bool>& stale) {
    for (int frame = 0; frame < 3 && !stale; ++frame) {
      std::this_thread::sleep_for(60ms);
      ++frames_run;
    }
  });
  r.start();
  wait_for([&] { return r.runs_finished() == 1; });
  const int before = r.runs_started();
  for (int i = 0; i < 10; ++i) {
    save(f, i);
    std::this_thread::sleep_for(40ms);
  }
  wait_for([&] { return r.saves_seen() >= 1 && r.runs_finished() == r.runs_started(); });
  std::this_thread::sleep_for(600ms);
  EXPECT_GE(r.saves_seen(), 3);
  EXPECT_GE(r.runs_started() - before, 1);
  EXPECT_LE(r.runs_started() - before, 2);
  r.stop();
  fs::remove(f);
}

TEST(Rerun, ASaveDuringARunMakesItStaleAndRunsAgain) {
  const fs::path f = test_file("stale");
  std::atomic<int> stopped_early{0};
  std::atomic<bool> first{true};
  Rerun r({f}, [&](const std::atomic<bool>& stale) {
    if (!first.exchange(false)) return;
    for (int i = 0; i < 300 && !stale; ++i) std::this_thread::sleep_for(10ms);
    if (stale) ++stopped_early;
  });
  r.start();
  wait_for([&] { return r.runs_started() == 1; });
  save(f, 1);
  wait_for([&] { return r.runs_finished() == 2; });
  EXPECT_EQ(stopped_early.load(), 1);
  EXPECT_EQ(r.runs_finished(), 2);
  r.stop();
  fs::remove(f);
}

TEST(Rerun, ASaveAfterAQuietTimeRunsAtOnceAndABurstWaitsForItsEnd) {
  const fs::path f = test_file("leading");
  RerunOptions o;
  o.settle = 3s;  // long, so that "at once" and "after the burst" cannot be confused
  Rerun r(
      {f}, [](const std::atomic<bool>&) {}, o);
  r.start();
  wait_for([&] { return r.runs_finished() == 1; });
  const auto t0 = std::chrono::steady_clock::now();
  save(f, 1);
  wait_for([&] { return r.runs_started() == 2; });
  EXPECT_EQ(r.runs_started(), 2);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2500ms) << "the first save waited to settle";
  // A second save right after: within the settle of the first, it waits for the burst's end.
  save(f, 2);
  std::this_thread::sleep_for(1000ms);
  EXPECT_EQ(r.runs_started(), 2);
  wait_for([&] { return r.runs_finished() == 3; });
  EXPECT_EQ(r.runs_finished(), 3);
  r.stop();
  fs::remove(f);
}

}  // namespace
}  // namespace emaki::view
