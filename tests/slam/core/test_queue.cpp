// The local mapper's queue: blocking pop, close() wakes the consumer, items
// pushed before close() are still delivered, pushes after it are refused.
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "pvb/slam/core/local_mapping.hpp"

namespace pvb::slam {
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

TEST(ClosableQueue, CloseWakesAnIdleConsumer) {
  ClosableQueue<int> q;
  std::thread consumer([&] { EXPECT_FALSE(q.pop().has_value()); });
  q.close();
  consumer.join();
}

}  // namespace
}  // namespace pvb::slam
