#include "skelgraph/runtime/security_policy.hpp"

#include <set>
#include <sstream>

#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::runtime::security {

const std::vector<std::string>& roles() {
  static const std::vector<std::string> r = {"master", "sensor", "reader", "robot", "robot-control"};
  return r;
}

// The robot's topics: only the robot host (its state) and the robot-control
// hosts (commands, the safety verdict) may publish them; even the master not.
std::vector<std::string> robot_topics() {
  namespace t = ::skelgraph::runtime::topics;
  return {t::kRobotState.name, t::kRobotCommand.name, t::kSafety.name};
}

// What a role may publish (every role may subscribe to everything).
std::vector<std::string> role_publishes(const std::string& role) {
  namespace t = ::skelgraph::runtime::topics;
  if (role == "master") return {"*"};
  if (role == "sensor") {
    return {t::kSkeletonRaw.name, t::kSkeletonTruth.name, t::kSensorFrame.name, t::kCalibration.name,
            t::kDepth.name,       t::kCloud.name,         t::kSyncAck.name,     t::kStatus.name,
            t::kPlayState.name};
  }
  if (role == "robot") return {t::kRobotState.name, t::kSyncAck.name, t::kStatus.name};
  if (role == "robot-control") return {t::kRobotCommand.name, t::kSafety.name, t::kSyncAck.name, t::kStatus.name};
  return {t::kSyncAck.name, t::kStatus.name};  // reader
}

// A host's grant from its roles: the union of what they publish; a master
// ("*") is denied the robot topics its other roles do not give it.
Grant grant_of(const std::vector<std::string>& roles) {
  Grant g;
  std::set<std::string> seen;
  for (const auto& r : roles)
    for (const auto& t : role_publishes(r))
      if (seen.insert(t).second) g.publish.push_back(t);
  if (seen.count("*")) {
    for (const auto& t : robot_topics())
      if (!seen.count(t)) g.deny.push_back(t);
  }
  return g;
}

namespace {
const char* kDomains = "<domains><id_range><min>0</min><max>232</max></id_range></domains>";
}  // namespace

std::string governance_xml() {
  return std::string(R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- skelgraph cell governance (skelgraph security init): only authenticated
     participants join; discovery, liveliness and all RTPS traffic encrypted;
     every topic under read and write access control. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      )") + kDomains + R"(
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
)";
}

std::string permissions_xml(const Hosts& hosts, const std::string& from, const std::string& until) {
  std::ostringstream x;
  x << R"(<?xml version="1.0" encoding="UTF-8"?>
<!-- skelgraph cell permissions (skelgraph security init): the sync master host
     may publish everything but the robot's topics; sensor hosts their sensors'
     topics; the robot host its state; robot-control hosts robot commands and
     the safety verdict; reader hosts only acks and status. Every host may
     subscribe to everything. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
)";
  for (const auto& [host, roles] : hosts) {
    const auto g = grant_of(roles);
    x << "    <grant name=\"" << host << "\">\n"
      << "      <subject_name>CN=" << host << "</subject_name>\n"
      << "      <validity><not_before>" << from << "</not_before><not_after>" << until << "</not_after></validity>\n";
    if (!g.deny.empty()) {
      x << "      <deny_rule>\n        " << kDomains << "\n        <publish><topics>";
      for (const auto& t : g.deny) x << "<topic>" << t << "</topic>";
      x << "</topics></publish>\n      </deny_rule>\n";
    }
    x << "      <allow_rule>\n        " << kDomains << "\n        <publish><topics>";
    for (const auto& t : g.publish) x << "<topic>" << t << "</topic>";
    x << "</topics></publish>\n        <subscribe><topics><topic>*</topic></topics></subscribe>\n"
      << "      </allow_rule>\n      <default>DENY</default>\n    </grant>\n";
  }
  x << "  </permissions>\n</dds>\n";
  return x.str();
}

bool valid_host(const std::string& h) {
  return !h.empty() && h.size() <= 64 && h.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.") == std::string::npos;
}

}  // namespace skelgraph::runtime::security
