#pragma once
// What one recording holds (`skelgraph bag info --json`): whether it is a
// valid MCAP file (and what is wrong if not), its indexes and what was read by
// scanning instead, messages and rate per topic, sync sessions and ticks,
// which host acknowledged which ticks, skeletons per sensor (and how many in
// an older schema), tick records, clock offsets and metadata. No DDS.

#include <string>

#include <nlohmann/json.hpp>

namespace skelgraph::recording {

// Throws mcap::McapError when the file cannot be read at all.
nlohmann::json recording_info(const std::string& file);

}  // namespace skelgraph::recording
