// BackgroundWorker: one job at a time, handed over without the owner ever waiting on the job.
#include "uh/core/background_worker.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

namespace uh {
namespace {

using Taken = BackgroundWorker::Taken;

// request() when the worker is idle: it only tries the lock, which the worker holds for a moment
// as it waits, so it may say no while idle; a few tries get through
template <class Fill>
bool request_when_idle(BackgroundWorker& worker, Fill&& fill) {
  for (int tries = 0; tries < 1000; ++tries) {
    if (worker.request(fill)) return true;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  return false;
}

// polls take() until the job has finished (the owner's calls never wait)
template <class Collect>
Taken take_when_finished(BackgroundWorker& worker, Collect&& collect) {
  for (int tries = 0; tries < 20000; ++tries) {
    if (const Taken t = worker.take(collect); t != Taken::kNothing) return t;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return Taken::kNothing;
}

TEST(BackgroundWorker, RunsOneJobAtATimeAndHandsItsOutputOver) {
  std::atomic<bool> release{false};
  int input = 0, output = 0;
  BackgroundWorker worker([&] {
    while (!release.load()) std::this_thread::sleep_for(std::chrono::microseconds(100));
    output = 2 * input;
    return true;
  });
  EXPECT_FALSE(worker.busy());
  EXPECT_EQ(worker.take([] {}), Taken::kNothing) << "nothing was asked for";
  ASSERT_TRUE(request_when_idle(worker, [&] { input = 21; }));
  EXPECT_TRUE(worker.busy());
  EXPECT_FALSE(worker.request([&] { input = 99; })) << "one job at a time";
  EXPECT_EQ(worker.take([] {}), Taken::kNothing) << "the job is still under way";
  release = true;
  int collected = 0;
  EXPECT_EQ(take_when_finished(worker, [&] { collected = output; }), Taken::kDone);
  EXPECT_EQ(collected, 42) << "the input of the first request, not of the refused one";
  EXPECT_FALSE(worker.busy());
  EXPECT_TRUE(request_when_idle(worker, [&] { input = 5; })) << "idle again once taken";
  EXPECT_EQ(take_when_finished(worker, [&] { collected = output; }), Taken::kDone);
  EXPECT_EQ(collected, 10);
}

TEST(BackgroundWorker, AFailedJobIsReportedAndItsOutputNotCollected) {
  BackgroundWorker worker([] { return false; });
  ASSERT_TRUE(request_when_idle(worker, [] {}));
  bool collected = false;
  EXPECT_EQ(take_when_finished(worker, [&] { collected = true; }), Taken::kFailed);
  EXPECT_FALSE(collected);
  EXPECT_TRUE(request_when_idle(worker, [] {}));
}

TEST(BackgroundWorker, EndsWithAJobUnderWay) {
  std::atomic<bool> started{false};
  std::atomic<int> finished{0};
  {
    BackgroundWorker worker([&] {
      started = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++finished;
      return true;
    });
    ASSERT_TRUE(request_when_idle(worker, [] {}));
    while (!started.load()) std::this_thread::yield();
  }  // the destructor waits for the job under way, then ends the thread
  EXPECT_EQ(finished.load(), 1);
}

}  // namespace
}  // namespace uh
