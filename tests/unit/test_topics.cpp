// The topic table as tools read it: every topic found by name, and a reading
// tool's plan (type, key, a history deep enough never to block a writer).
#include <gtest/gtest.h>

#include "skelgraph/runtime/topics.hpp"

using namespace skelgraph;

TEST(Topics, EveryKnownTopicIsFoundByNameAndNothingElse) {
  ASSERT_FALSE(runtime::known_topics().empty());
  for (const auto& t : runtime::known_topics()) {
    const auto* found = runtime::find_topic(t.name);
    ASSERT_NE(found, nullptr) << t.name;
    EXPECT_EQ(found->type_name, t.type_name);
  }
  EXPECT_EQ(runtime::find_topic("skelgraph/nope"), nullptr);
  EXPECT_EQ(runtime::find_topic("rt/skelgraph/sync"), nullptr);
}

TEST(Topics, AReadingToolsPlanKeepsTheTypeAndKeyAndDeepensTheHistory) {
  const auto fused = runtime::reader_plan(*runtime::find_topic(runtime::topics::kSkeletonFused.name), 100, 1000);
  EXPECT_EQ(fused.type_name, msg::MessageTraits<msg::Skeleton>::name);
  EXPECT_TRUE(fused.keyed);  // one instance per person
  EXPECT_EQ(fused.qos.depth, 100);  // 5 deepened
  EXPECT_EQ(fused.qos.reliability, runtime::topics::kSkeletonFused.qos.reliability);
  EXPECT_EQ(fused.qos.max_instances, runtime::topics::kSkeletonFused.qos.max_instances);

  const auto sync = runtime::reader_plan(*runtime::find_topic(runtime::topics::kSync.name), 256, 256);
  EXPECT_FALSE(sync.keyed);
  EXPECT_EQ(sync.qos.depth, 256);  // keep-all becomes a bounded history
  EXPECT_EQ(runtime::reader_plan(*runtime::find_topic(runtime::topics::kSync.name), 256, 0).qos.depth, 0);  // or stays keep-all

  runtime::TopicInfo deep{"x", msg::MessageTraits<msg::SyncCommand>::name, runtime::topics::kSync.qos};
  deep.qos.depth = 500;
  EXPECT_EQ(runtime::reader_plan(deep, 100, 1000).qos.depth, 500);  // already deeper: kept
  runtime::TopicInfo unknown{"x", "no::SuchType", deep.qos};
  EXPECT_FALSE(runtime::reader_plan(unknown, 1, 1).keyed);
}
