// The controllers' "call with mutex_ held" is checked: CheckedMutex knows which thread holds it,
// and AssertHeld stops the program, naming the function, when the caller does not.
#include <gtest/gtest.h>

#include <mutex>
#include <thread>

#include "ui/state/checked_mutex.h"

namespace calibench::ui {
namespace {

TEST(CheckedMutex, KnowsWhichThreadHoldsIt) {
  CheckedMutex mutex;
  EXPECT_FALSE(mutex.HeldByThisThread());
  {
    std::lock_guard lock(mutex);
    EXPECT_TRUE(mutex.HeldByThisThread());
    bool held_elsewhere = true;
    std::thread other([&] { held_elsewhere = mutex.HeldByThisThread(); });
    other.join();
    EXPECT_FALSE(held_elsewhere) << "another thread does not hold it";
    mutex.AssertHeld("the holder");  // returns
  }
  EXPECT_FALSE(mutex.HeldByThisThread());
  ASSERT_TRUE(mutex.try_lock());
  EXPECT_TRUE(mutex.HeldByThisThread());
  bool taken_elsewhere = true;
  std::thread other([&] { taken_elsewhere = mutex.try_lock(); });
  other.join();
  EXPECT_FALSE(taken_elsewhere);
  mutex.unlock();
}

TEST(CheckedMutexDeathTest, ACallWithoutTheLockStopsNamingTheFunction) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  CheckedMutex mutex;
  EXPECT_DEATH(mutex.AssertHeld("RecomputeResiduals"),
               "RecomputeResiduals called without the controller's lock held");
}

}  // namespace
}  // namespace calibench::ui
