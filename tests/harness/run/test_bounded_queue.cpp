// The producer/consumer queue of scenario runs: order, bound, closing.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "pvb/run/bounded_queue.hpp"

namespace pvb::run {
namespace {

TEST(BoundedQueue, DeliversInOrderThenEndsOnClose) {
  BoundedQueue<int> q(3);
  EXPECT_TRUE(q.push(1));
  EXPECT_TRUE(q.push(2));
  q.close();
  EXPECT_FALSE(q.push(3));  // refused after close
  EXPECT_EQ(q.pop(), 1);
  EXPECT_EQ(q.pop(), 2);    // drained after close
  EXPECT_EQ(q.pop(), std::nullopt);
}

TEST(BoundedQueue, ProducerNeverRunsMoreThanCapacityAhead) {
  BoundedQueue<int> q(2);
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

TEST(BoundedQueue, CloseAndClearReleasesABlockedProducer) {
  BoundedQueue<int> q(1);
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
  EXPECT_EQ(q.pop(), std::nullopt);  // cleared
}

TEST(BoundedQueue, CloseWakesAnIdleConsumer) {
  BoundedQueue<int> q(4);
  std::optional<int> got = 7;
  std::thread consumer([&] { got = q.pop(); });
  q.close();
  consumer.join();
  EXPECT_EQ(got, std::nullopt);
}

}  // namespace
}  // namespace pvb::run
