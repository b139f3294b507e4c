// The workbench's one worker (ui/state/work_queue.h): queued jobs in order, background jobs below
// them (a rig solve's steps, a followed capture's looks), cancelled without a step slipping
// through.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ui/state/work_queue.h"

namespace calibench::ui {
namespace {

class Recorder {
 public:
  void Add(const std::string& what) {
    std::lock_guard lock(mutex_);
    order_.push_back(what);
  }
  std::vector<std::string> Order() const {
    std::lock_guard lock(mutex_);
    return order_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> order_;
};

TEST(WorkQueue, BackgroundJobsRunOnlyWhenNoQueuedJobWaits) {
  WorkQueue queue(nullptr);
  Recorder recorder;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  // The worker is held while the rest is enqueued: a background job enqueued before a queued one
  // still runs after it.
  queue.Enqueue([&, released] {
    released.wait();
    recorder.Add("edit 1");
  });
  queue.EnqueueBackground("rig", [&] { recorder.Add("rig step"); });
  queue.Enqueue([&] { recorder.Add("edit 2"); });
  EXPECT_TRUE(queue.Busy());
  EXPECT_TRUE(queue.BackgroundPending("rig"));
  release.set_value();
  queue.WaitIdle();  // waits for the background job too: it is due
  EXPECT_EQ(recorder.Order(), (std::vector<std::string>{"edit 1", "edit 2", "rig step"}));
  EXPECT_FALSE(queue.BackgroundPending("rig"));
  EXPECT_FALSE(queue.Busy());
}

TEST(WorkQueue, AStepThatEnqueuesItsSuccessorLetsQueuedJobsIn) {
  WorkQueue queue(nullptr);
  Recorder recorder;
  std::atomic<int> steps{0};
  std::function<void()> step = [&] {
    const int k = ++steps;
    recorder.Add("step " + std::to_string(k));
    if (k == 1) queue.Enqueue([&] { recorder.Add("edit"); });  // the user brushes meanwhile
    if (k < 3) queue.EnqueueBackground("rig", step);
  };
  queue.EnqueueBackground("rig", step);
  queue.WaitIdle();
  EXPECT_EQ(recorder.Order(), (std::vector<std::string>{"step 1", "edit", "step 2", "step 3"}))
      << "the edit waits for one step, not for the whole chain";
}

TEST(WorkQueue, ADelayedJobIsNotWaitedForAndCancelDropsIt) {
  WorkQueue queue(nullptr);
  std::atomic<bool> ran{false};
  queue.EnqueueBackground(
      "follow", [&] { ran = true; }, /*delay_s=*/60.0);
  queue.WaitIdle();  // returns: the next look is not due
  EXPECT_FALSE(ran);
  EXPECT_TRUE(queue.BackgroundPending("follow"));
  EXPECT_FALSE(queue.Busy()) << "a look waiting for its time is not work the window waits on";
  queue.CancelBackground("follow");
  EXPECT_FALSE(queue.BackgroundPending("follow"));
  EXPECT_FALSE(ran);
}

TEST(WorkQueue, CancelWaitsForTheRunningStepAndDropsTheSuccessorItEnqueued) {
  WorkQueue queue(nullptr);
  std::atomic<int> steps{0};
  std::promise<void> started;
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::function<void()> look = [&, released] {
    if (++steps == 1) {
      started.set_value();
      released.wait();
    }
    queue.EnqueueBackground("follow", look, 0.5);  // the next look
  };
  queue.EnqueueBackground("follow", look);
  started.get_future().wait();
  std::thread canceller([&] { queue.CancelBackground("follow"); });
  // The canceller is blocked on the running look; let it finish (it enqueues its successor).
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  release.set_value();
  canceller.join();
  const int after_cancel = steps;
  EXPECT_EQ(after_cancel, 1);
  EXPECT_FALSE(queue.BackgroundPending("follow"));
  queue.Enqueue([] {});
  queue.WaitIdle();
  EXPECT_EQ(steps, after_cancel) << "no look ran after CancelBackground returned";
}

TEST(WorkQueue, WaitIdleFromABackgroundJobReturnsFromAQueuedOneIsAnError) {
  std::mutex errors_mutex;
  std::vector<std::string> errors;
  WorkQueue queue([&](const std::string& message) {
    std::lock_guard lock(errors_mutex);
    errors.push_back(message);
  });
  std::atomic<bool> returned{false};
  queue.EnqueueBackground("follow", [&] {
    queue.WaitIdle();  // an opened capture's Open waits for the last dataset's jobs: none
    returned = true;
  });
  queue.WaitIdle();
  EXPECT_TRUE(returned);
  queue.Enqueue([&] { queue.WaitIdle(); });
  queue.WaitIdle();
  std::lock_guard lock(errors_mutex);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("WaitIdle from a queued job"), std::string::npos) << errors[0];
}

TEST(WorkQueue, StopDropsBackgroundJobs) {
  std::atomic<bool> ran{false};
  {
    WorkQueue queue(nullptr);
    std::promise<void> release;
    std::shared_future<void> released = release.get_future().share();
    queue.Enqueue([released] { released.wait(); });
    queue.EnqueueBackground("rig", [&] { ran = true; });
    std::thread stopper([&] { queue.Stop(); });
    // Stop drops the background job at once, then waits for the running one.
    for (int i = 0; i < 10000 && queue.BackgroundPending("rig"); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    EXPECT_FALSE(queue.BackgroundPending("rig"));
    release.set_value();
    stopper.join();
    queue.EnqueueBackground("rig", [&] { ran = true; });  // after Stop: dropped
  }
  EXPECT_FALSE(ran);
}

}  // namespace
}  // namespace calibench::ui
