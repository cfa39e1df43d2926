// The processing thread's helper (core/pipeline/helper_thread.h): each job runs on one other
// thread, whole, before wait() returns; jobs run one after another in the order given.
#include "core/pipeline/helper_thread.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <set>
#include <thread>
#include <vector>

namespace arpipe {
namespace {

TEST(HelperThread, RunsEachJobOnOneOtherThreadAndWaitReturnsAfterIt) {
  HelperThread helper;
  std::set<std::thread::id> ran_on;
  std::vector<int> order;
  for (int job = 0; job < 200; ++job) {
    bool done = false;
    helper.start([&, job] {
      if (job % 50 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // slower than the caller
      ran_on.insert(std::this_thread::get_id());
      order.push_back(job);
      done = true;
    });
    helper.wait();
    ASSERT_TRUE(done) << "wait() returned before job " << job << " finished";
  }
  ASSERT_EQ(ran_on.size(), 1u);
  EXPECT_NE(*ran_on.begin(), std::this_thread::get_id());
  ASSERT_EQ(order.size(), 200u);
  for (int job = 0; job < 200; ++job) EXPECT_EQ(order[size_t(job)], job);
  helper.wait();  // with nothing started: at once
}

TEST(HelperThread, StartWaitsForTheJobBeforeAndTheDestructorForTheLast) {
  std::atomic<int> finished{0};
  {
    HelperThread helper;
    helper.start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = 1;
    });
    helper.start([&] { finished = finished == 1 ? 2 : -1; });  // only after the first has finished
    helper.start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = finished == 2 ? 3 : -1;
    });
  }  // not waited for: the destructor does
  EXPECT_EQ(finished, 3);
}

}  // namespace
}  // namespace arpipe
