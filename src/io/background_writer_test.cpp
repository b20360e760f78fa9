#include "io/background_writer.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace emaki::io {
namespace {

// Jobs run one at a time in the order given, and a queued job's files count as pending.
TEST(BackgroundWriter, RunsJobsInOrderAndKnowsWhatIsPending) {
  std::vector<int> order;
  std::atomic<bool> release{false};
  BackgroundWriter w(8);
  w.submit({"a"}, [&] {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    order.push_back(0);
  });
  const std::string names[] = {"", "f1", "f2", "f3", "f4"};
  for (int i = 1; i < 5; ++i) w.submit({names[i]}, [&order, i] { order.push_back(i); });
  EXPECT_TRUE(w.pending("a"));
  EXPECT_TRUE(w.pending("f4"));
  EXPECT_FALSE(w.pending("b"));
  release = true;
  w.wait();
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_FALSE(w.pending("f4"));
}

// A failed write is reported once, by the next call; the jobs queued after it do not run (the
// files on disk stay a prefix of the order).
TEST(BackgroundWriter, ReportsAFailedWriteAndStops) {
  std::atomic<int> ran{0};
  std::atomic<bool> release{false};
  BackgroundWriter w(8);
  w.submit({"a"}, [&] {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    throw std::runtime_error("disk full");
  });
  w.submit({"b"}, [&] { ++ran; });
  release = true;
  EXPECT_THROW(w.wait(), std::runtime_error);
  EXPECT_EQ(ran, 0);
  w.wait();  // reported once
  w.submit({"c"}, [&] { ++ran; });
  w.wait();
  EXPECT_EQ(ran, 1);
  // An error is also reported by the next submit.
  w.submit({"d"}, [] { throw std::runtime_error("gone"); });
  while (w.pending("d")) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_THROW(w.submit({"e"}, [] {}), std::runtime_error);
}

// At most max_pending jobs wait: submit blocks until one ran.
TEST(BackgroundWriter, BoundsTheQueue) {
  std::atomic<bool> release{false};
  std::atomic<int> submitted{0};
  BackgroundWriter w(2);
  w.submit({}, [&] {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  w.submit({}, [] {});
  std::thread t([&] {
    w.submit({}, [] {});
    ++submitted;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(submitted, 0);
  release = true;
  t.join();
  EXPECT_EQ(submitted, 1);
  w.wait();
}

}  // namespace
}  // namespace emaki::io
