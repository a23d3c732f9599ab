// The one time-ordered queue: time order across streams, ties in push order,
// held back only as far as a stream's lateness and the slowest stream require.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "skelgraph/runtime/ordered_queue.hpp"

using skelgraph::runtime::OrderedQueue;

namespace {
template <class Q>
std::vector<std::pair<std::int64_t, std::string>> drained(Q& q, bool flush = false) {
  std::vector<std::pair<std::int64_t, std::string>> out;
  const auto take = [&](std::int64_t t, std::string&& s) { out.emplace_back(t, std::move(s)); };
  if (flush) q.flush(take);
  else q.drain(take);
  return out;
}
using Out = std::vector<std::pair<std::int64_t, std::string>>;
}  // namespace

TEST(OrderedQueue, OneStreamIsReorderedWithinItsLateness) {
  OrderedQueue<std::string> q;
  q.add_stream(0, 10);
  q.push(0, 100, "a");
  EXPECT_TRUE(drained(q).empty());  // 100 > 100 - 10: a later push may still come before it
  q.push(0, 95, "b");                // late, within the lateness
  q.push(0, 112, "c");
  EXPECT_EQ(drained(q), (Out{{95, "b"}, {100, "a"}}));
  q.push(0, 112, "d");  // a tie: in push order
  q.push(0, 130, "e");
  EXPECT_EQ(drained(q), (Out{{112, "c"}, {112, "d"}}));
  EXPECT_EQ(q.size(), 1u);
  EXPECT_EQ(drained(q, true), (Out{{130, "e"}}));
  EXPECT_TRUE(q.empty());
}

TEST(OrderedQueue, StreamsMergeInTimeOrderAndTheSlowestHoldsBack) {
  OrderedQueue<std::string, std::string> q;
  q.add_stream("host_a");
  q.add_stream("host_b", 5);
  q.push("host_a", 10, "a10");
  q.push("host_a", 20, "a20");
  EXPECT_TRUE(drained(q).empty());  // host_b has said nothing yet
  EXPECT_EQ(q.blocker(), std::optional<std::string>("host_b"));
  q.push("host_b", 16, "b16");
  EXPECT_EQ(drained(q), (Out{{10, "a10"}}));  // b can still bring 11..16; a has passed 20
  EXPECT_EQ(q.blocker(), std::optional<std::string>("host_b"));
  q.push("host_b", 40, "b40");
  EXPECT_EQ(drained(q), (Out{{16, "b16"}, {20, "a20"}}));
  EXPECT_EQ(q.blocker(), std::optional<std::string>("host_a"));  // a at 20, b at 40 - 5
  q.finish("host_a");
  EXPECT_TRUE(drained(q).empty());  // b alone: its own lateness still holds 40 back (40 > 40 - 5)
  q.finish("host_b");
  EXPECT_EQ(drained(q), (Out{{40, "b40"}}));
  EXPECT_FALSE(q.blocker().has_value());
  EXPECT_THROW(q.push("host_b", 50, "late"), std::logic_error);
}

TEST(OrderedQueue, ItemsAreMovedNotCopied) {
  OrderedQueue<std::unique_ptr<int>> q;
  q.push(7, 2, std::make_unique<int>(2));
  q.push(7, 1, std::make_unique<int>(1));
  std::vector<int> got;
  q.flush([&](std::int64_t, std::unique_ptr<int>&& p) { got.push_back(*p); });
  EXPECT_EQ(got, (std::vector<int>{1, 2}));
}
