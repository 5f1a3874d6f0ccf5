// The closable queue of the worker threads (unbounded) and of scenario runs
// (bounded): order, closing, the bound, and waking blocked threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "pvb/common/closable_queue.hpp"

namespace pvb {
namespace {

TEST(ClosableQueue, DeliversInOrderThenEndsOnClose) {
  ClosableQueue<int> q;
  std::vector<int> got;
  std::thread consumer([&] {
    while (auto v = q.pop()) got.push_back(*v);
  });
  for (int i = 0; i < 100; ++i) EXPECT_TRUE(q.push(i));
  q.close();
  consumer.join();  // would hang if close() did not wake the consumer
  ASSERT_EQ(got.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(got[static_cast<std::size_t>(i)], i);
  EXPECT_FALSE(q.push(7));
  EXPECT_FALSE(q.pop().has_value());
}

TEST(ClosableQueue, ItemsPushedBeforeCloseAreDrained) {
  ClosableQueue<int> q(3);
  EXPECT_TRUE(q.push(1));
  EXPECT_TRUE(q.push(2));
  q.close();
  EXPECT_FALSE(q.push(3));  // refused after close
  EXPECT_EQ(q.pop(), 1);
  EXPECT_EQ(q.pop(), 2);  // drained after close
  EXPECT_EQ(q.pop(), std::nullopt);
}

TEST(ClosableQueue, UnboundedPushNeverWaits) {
  ClosableQueue<int> q;
  EXPECT_EQ(q.capacity(), 0u);
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(q.push(i));  // no consumer: would hang if bounded
  EXPECT_EQ(q.size(), 1000u);
}

TEST(ClosableQueue, ProducerNeverRunsMoreThanCapacityAhead) {
  ClosableQueue<int> q(2);
  std::atomic<int> max_size{0};
  std::thread producer([&] {
    for (int i = 0; i < 200; ++i) {
      ASSERT_TRUE(q.push(i));
      max_size = std::max<int>(max_size, static_cast<int>(q.size()));
    }
    q.close();
  });
  int expected = 0;
  while (std::optional<int> v = q.pop()) EXPECT_EQ(*v, expected++);
  producer.join();
  EXPECT_EQ(expected, 200);
  EXPECT_LE(max_size.load(), 2);
}

TEST(ClosableQueue, CloseAndClearReleasesABlockedProducer) {
  ClosableQueue<int> q(1);
  ASSERT_TRUE(q.push(0));
  std::atomic<bool> returned{false}, result{true};
  std::thread producer([&] {
    result = q.push(1);  // blocks: the queue is full
    returned = true;
  });
  q.close_and_clear();  // the consumer stops early
  producer.join();
  EXPECT_TRUE(returned);
  EXPECT_FALSE(result);
  EXPECT_TRUE(q.closed());
  EXPECT_EQ(q.pop(), std::nullopt);  // cleared
}

TEST(ClosableQueue, CloseWakesAnIdleConsumer) {
  for (std::size_t capacity : {0u, 4u}) {
    ClosableQueue<int> q(capacity);
    std::optional<int> got = 7;
    std::thread consumer([&] { got = q.pop(); });
    q.close();
    consumer.join();
    EXPECT_EQ(got, std::nullopt) << "capacity " << capacity;
  }
}

}  // namespace
}  // namespace pvb
