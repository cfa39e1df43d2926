// BoundedQueue tests: Block loses nothing and keeps each producer's order, DropOldest keeps the
// newest items and counts every drop, close() wakes blocked pushers and poppers, pop drains after close.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/pipeline/bounded_queue.h"

namespace arpipe {
namespace {

// Only used to give a blocked thread the chance to (wrongly) run on; no assertion depends on timing:
// a correct queue passes however long or short this is.
void give_other_threads_a_chance() { std::this_thread::sleep_for(std::chrono::milliseconds(20)); }

TEST(BoundedQueue, BlockPolicyBlocksTheProducerWhenFull) {
  BoundedQueue<int> queue(2, OverflowPolicy::Block);
  ASSERT_TRUE(queue.push(1));
  ASSERT_TRUE(queue.push(2));
  std::atomic<bool> third_pushed{false};
  std::thread producer([&] {
    EXPECT_TRUE(queue.push(3));
    third_pushed = true;
  });
  give_other_threads_a_chance();
  EXPECT_FALSE(third_pushed) << "push() returned although the queue was full";
  EXPECT_EQ(queue.size(), 2u);

  EXPECT_EQ(queue.pop(), 1);  // makes room: the blocked push goes through
  producer.join();
  EXPECT_TRUE(third_pushed);
  EXPECT_EQ(queue.pop(), 2);
  EXPECT_EQ(queue.pop(), 3);
  EXPECT_EQ(queue.dropped(), 0u);
}

TEST(BoundedQueue, BlockPolicyLosesNothingAndKeepsEachProducersOrder) {
  constexpr int kProducers = 3;
  constexpr int kItemsEach = 20'000;
  struct Item {
    int producer;
    int index;
  };
  BoundedQueue<Item> queue(4, OverflowPolicy::Block);  // small, so producers block often
  std::vector<std::thread> producers;
  for (int p = 0; p < kProducers; ++p)
    producers.emplace_back([&queue, p] {
      for (int i = 0; i < kItemsEach; ++i) ASSERT_TRUE(queue.push({p, i}));
    });

  std::vector<int> next_expected(kProducers, 0);
  int received = 0;
  std::thread consumer([&] {
    while (auto item = queue.pop()) {
      ASSERT_GE(item->producer, 0);
      ASSERT_LT(item->producer, kProducers);
      // Items of one producer arrive in the order pushed, with none missing in between.
      ASSERT_EQ(item->index, next_expected[size_t(item->producer)]) << "producer " << item->producer;
      ++next_expected[size_t(item->producer)];
      ++received;
    }
  });
  for (auto& t : producers) t.join();
  queue.close();
  consumer.join();

  EXPECT_EQ(received, kProducers * kItemsEach);
  for (int p = 0; p < kProducers; ++p) EXPECT_EQ(next_expected[size_t(p)], kItemsEach);
  EXPECT_EQ(queue.dropped(), 0u);
}

TEST(BoundedQueue, DropOldestKeepsTheNewestItemsAndCountsDrops) {
  BoundedQueue<int> queue(3, OverflowPolicy::DropOldest);
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(queue.push(i));  // never blocks
  EXPECT_EQ(queue.size(), 3u);
  EXPECT_EQ(queue.dropped(), 7u);
  queue.close();
  EXPECT_EQ(queue.pop(), 7);
  EXPECT_EQ(queue.pop(), 8);
  EXPECT_EQ(queue.pop(), 9);
  EXPECT_EQ(queue.pop(), std::nullopt);
}

// The drop handler is handed each dropped item, the oldest first, and nothing else: the pipeline
// gives a dropped frame's memory back to the source through it.
TEST(BoundedQueue, DropOldestHandsEachDroppedItemToTheDropHandler) {
  std::vector<std::string> dropped;
  BoundedQueue<std::string> queue(2, OverflowPolicy::DropOldest, [&](std::string&& s) { dropped.push_back(std::move(s)); });
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(queue.push(std::to_string(i)));
  EXPECT_EQ(dropped, (std::vector<std::string>{"0", "1", "2"}));
  EXPECT_EQ(queue.dropped(), 3u);
  queue.close();
  EXPECT_FALSE(queue.push("5"));  // refused after close: not a drop
  EXPECT_EQ(dropped.size(), 3u);
  EXPECT_EQ(queue.pop(), "3");
  EXPECT_EQ(queue.pop(), "4");
}

TEST(BoundedQueue, DropOldestCountsEveryDropUnderConcurrency) {
  constexpr int kItems = 50'000;
  BoundedQueue<int> queue(2, OverflowPolicy::DropOldest);
  std::vector<int> received;
  std::thread consumer([&] {
    while (auto item = queue.pop()) received.push_back(*item);
  });
  for (int i = 0; i < kItems; ++i) ASSERT_TRUE(queue.push(i));
  queue.close();
  consumer.join();

  // Whatever the interleaving: every item was either delivered or counted as dropped, exactly once,
  // the delivered ones in order, and the newest one is never the one dropped.
  EXPECT_EQ(received.size() + queue.dropped(), size_t(kItems));
  for (size_t i = 1; i < received.size(); ++i) ASSERT_LT(received[i - 1], received[i]);
  ASSERT_FALSE(received.empty());
  EXPECT_EQ(received.back(), kItems - 1);
}

TEST(BoundedQueue, ZeroCapacityMeansOne) {
  BoundedQueue<int> queue(0, OverflowPolicy::DropOldest);
  queue.push(1);
  queue.push(2);
  EXPECT_EQ(queue.size(), 1u);
  EXPECT_EQ(queue.dropped(), 1u);
  EXPECT_EQ(queue.pop(), 2);
}

TEST(BoundedQueue, CloseWakesABlockedPush) {
  BoundedQueue<int> queue(1, OverflowPolicy::Block);
  ASSERT_TRUE(queue.push(1));
  std::atomic<int> push_result{-1};
  std::thread producer([&] { push_result = queue.push(2) ? 1 : 0; });
  give_other_threads_a_chance();
  EXPECT_EQ(push_result, -1) << "push() into a full Block queue returned early";
  queue.close();
  producer.join();
  EXPECT_EQ(push_result, 0);  // closed: the item is discarded
  EXPECT_EQ(queue.pop(), 1);
  EXPECT_EQ(queue.pop(), std::nullopt);
}

TEST(BoundedQueue, CloseWakesABlockedPop) {
  for (auto policy : {OverflowPolicy::Block, OverflowPolicy::DropOldest}) {
    BoundedQueue<int> queue(2, policy);
    std::atomic<bool> popped{false};
    std::optional<int> result = 42;
    std::thread consumer([&] {
      result = queue.pop();
      popped = true;
    });
    give_other_threads_a_chance();
    EXPECT_FALSE(popped) << "pop() on an empty open queue returned early";
    queue.close();
    consumer.join();
    EXPECT_EQ(result, std::nullopt);
  }
}

TEST(BoundedQueue, PopDrainsAfterCloseThenReturnsNullopt) {
  for (auto policy : {OverflowPolicy::Block, OverflowPolicy::DropOldest}) {
    BoundedQueue<std::string> queue(4, policy);
    queue.push("a");
    queue.push("b");
    queue.push("c");
    queue.close();
    EXPECT_FALSE(queue.push("d"));  // refused after close
    EXPECT_EQ(queue.pop(), "a");
    EXPECT_EQ(queue.pop(), "b");
    EXPECT_EQ(queue.pop(), "c");
    EXPECT_EQ(queue.pop(), std::nullopt);
    EXPECT_EQ(queue.pop(), std::nullopt);  // and stays so
    EXPECT_EQ(queue.dropped(), 0u);
  }
}

}  // namespace
}  // namespace arpipe
