#pragma once
// The demo report's sections beyond the fusion tables (`skelgraph demo`):
// pointing spotted in simulated sessions the built-in model never saw, with
// its false alarms during work without gestures; and the robot cell's
// speed-and-separation monitoring closed loop, judged against the truth,
// with its timeline. Each gives its figures (JSON) and its HTML. No DDS.

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace skelgraph::eval {

struct ReportSection {
  nlohmann::json summary;
  std::string html;
};

// The built-in pointing model ("sim") on 4 held-out sessions and 4 quiet sessions of each scenario, with its
// operating curve (recall against false events per hour); writes pointing_curve.svg into `dir`.
ReportSection pointing_section(const std::filesystem::path& dir);
// The robot cell of bringup/robot_cell.yaml with two workers; writes robot_separation.svg and robot_state.svg into `dir`.
ReportSection robot_section(const std::filesystem::path& dir);

}  // namespace skelgraph::eval
