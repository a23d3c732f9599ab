// The cell's DDS Security policy (runtime/security_policy.hpp): who may
// publish what. The robot's topics only from the robot host and
// robot-control hosts; a master everything else (a deny rule for them, ahead
// of its allow rule); a reader only acks and status.
#include <gtest/gtest.h>

#include <algorithm>

#include "skelgraph/runtime/security_policy.hpp"

using namespace skelgraph::runtime::security;

namespace {
bool has(const std::vector<std::string>& v, const std::string& x) { return std::find(v.begin(), v.end(), x) != v.end(); }
}  // namespace

TEST(SecurityPolicy, TheRobotsTopicsOnlyFromTheRobotAndRobotControl) {
  EXPECT_EQ(roles().size(), 5u);
  const auto master = grant_of({"master"});
  EXPECT_EQ(master.publish, std::vector<std::string>{"*"});
  EXPECT_EQ(master.deny, robot_topics());
  // Master and robot-control: commands and the verdict allowed, the robot's state still denied.
  const auto both = grant_of({"master", "robot-control"});
  EXPECT_EQ(both.deny, std::vector<std::string>{"skelgraph/robot/state"});
  EXPECT_TRUE(has(both.publish, "skelgraph/robot/command") && has(both.publish, "skelgraph/safety"));
  const auto robot = grant_of({"robot"});
  EXPECT_TRUE(robot.deny.empty());
  EXPECT_TRUE(has(robot.publish, "skelgraph/robot/state"));
  EXPECT_FALSE(has(robot.publish, "skelgraph/robot/command"));
  const auto sensor = grant_of({"sensor"});
  EXPECT_TRUE(has(sensor.publish, "skelgraph/skeleton/raw"));
  for (const auto& t : robot_topics()) EXPECT_FALSE(has(sensor.publish, t)) << t;
  EXPECT_EQ(grant_of({"reader"}).publish, (std::vector<std::string>{"skelgraph/sync_ack", "skelgraph/status"}));
  // Roles given twice publish each topic once.
  EXPECT_EQ(grant_of({"sensor", "sensor"}).publish.size(), sensor.publish.size());
}

TEST(SecurityPolicy, PermissionsPutTheDenyRuleBeforeTheAllowRule) {
  const auto x = permissions_xml({{"fusion", {"master"}}, {"arm", {"robot"}}}, "2026-01-01T00:00:00", "2027-01-01T00:00:00");
  const auto fusion = x.find("<grant name=\"fusion\">"), arm = x.find("<grant name=\"arm\">");
  ASSERT_NE(fusion, std::string::npos);
  ASSERT_NE(arm, std::string::npos);
  const auto deny = x.find("<deny_rule>", fusion), allow = x.find("<allow_rule>", fusion);
  ASSERT_LT(deny, allow);
  EXPECT_LT(allow, arm);
  EXPECT_NE(x.find("<topic>skelgraph/robot/state</topic>", deny), std::string::npos);
  EXPECT_EQ(x.find("<deny_rule>", arm), std::string::npos);  // the robot host: nothing to deny
  EXPECT_NE(x.find("<subject_name>CN=arm</subject_name>"), std::string::npos);
  EXPECT_NE(x.find("<not_after>2027-01-01T00:00:00</not_after>"), std::string::npos);
  EXPECT_NE(governance_xml().find("<allow_unauthenticated_participants>false"), std::string::npos);
  EXPECT_TRUE(valid_host("sensor-1.cell_a"));
  EXPECT_FALSE(valid_host(""));
  EXPECT_FALSE(valid_host("a b"));
  EXPECT_FALSE(valid_host(std::string(65, 'a')));
}
