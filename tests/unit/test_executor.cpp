#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "skelgraph/runtime/executor.hpp"

using namespace skelgraph::runtime;
using namespace std::chrono_literals;

namespace {
// Waits (bounded) until `pred` holds; never a bare sleep.
template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout = 5000ms) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::yield();
  }
  return pred();
}
}  // namespace

TEST(Executor, RunsPostedTasksInOrderOnOneThread) {
  Executor ex("t");
  std::vector<int> order;
  std::set<std::thread::id> threads;
  std::mutex m;
  for (int i = 0; i < 100; ++i) {
    ex.post([&, i] {
      std::lock_guard<std::mutex> l(m);
      order.push_back(i);
      threads.insert(std::this_thread::get_id());
    });
  }
  ex.start();
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  std::lock_guard<std::mutex> l(m);
  ASSERT_EQ(order.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(order[i], i);
  EXPECT_EQ(threads.size(), 1u);
  EXPECT_EQ(threads.count(std::this_thread::get_id()), 0u);
}

TEST(Executor, TimerFiresRepeatedlyAndStopsWhenCancelled) {
  Executor ex("t");
  ex.start();
  std::atomic<int> n{0};
  auto timer = ex.every(1ms, [&] { ++n; });
  ASSERT_TRUE(eventually([&] { return n.load() >= 5; }));
  timer.cancel();
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));  // any firing in progress has finished
  const int after = n.load();
  // The executor keeps running other work, the timer does not come back.
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  ex.post([] {});
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  EXPECT_EQ(n.load(), after);
}

TEST(Executor, TimerHandleDestructionCancels) {
  Executor ex("t");
  ex.start();
  std::atomic<int> n{0};
  {
    auto timer = ex.every(1ms, [&] { ++n; }, true);
    ASSERT_TRUE(eventually([&] { return n.load() >= 1; }));
  }
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  const int after = n.load();
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  EXPECT_EQ(n.load(), after);
}

TEST(Executor, TimerMayCancelItself) {
  Executor ex("t");
  ex.start();
  std::atomic<int> n{0};
  TimerHandle timer;
  std::mutex m;
  {
    std::lock_guard<std::mutex> l(m);
    timer = ex.every(1ms, [&] {
      if (++n == 3) timer.cancel();
    });
  }
  ASSERT_TRUE(eventually([&] { return n.load() >= 3; }));
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  EXPECT_EQ(n.load(), 3);
}

TEST(Executor, StopRunsQueuedWorkThenTheLastTaskAndDropsLaterPosts) {
  Executor ex("t");
  std::vector<int> seen;
  ex.post([&] { seen.push_back(1); });
  ex.start();
  ex.stop([&] { seen.push_back(2); });
  EXPECT_FALSE(ex.running());
  ex.post([&] { seen.push_back(3); });
  EXPECT_EQ(seen, (std::vector<int>{1, 2}));
  EXPECT_FALSE(ex.run_sync([] {}, 10ms));
  ex.stop();  // idempotent
}

TEST(Executor, AnExceptionInATaskOrTimerIsReportedAndTheExecutorGoesOn) {
  Executor ex("t");
  std::mutex m;
  std::vector<std::string> errors;
  ex.on_error([&](const std::string& what) {
    std::lock_guard<std::mutex> l(m);
    errors.push_back(what);
  });
  std::atomic<int> after{0};
  ex.post([] { throw std::runtime_error("disk full"); });
  ex.post([&] { ++after; });
  std::atomic<int> ticks{0};
  auto timer = ex.every(1ms, [&] {
    if (++ticks == 1) throw std::runtime_error("timer failed");
  });
  ex.start();
  ASSERT_TRUE(eventually([&] { return ticks.load() >= 3; }));
  timer.cancel();
  ASSERT_TRUE(ex.run_sync([] {}, 5000ms));
  EXPECT_EQ(after.load(), 1);
  std::lock_guard<std::mutex> l(m);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0], "disk full");
  EXPECT_EQ(errors[1], "timer failed");
}
