#include "skelgraph/recording/info.hpp"

#include <map>
#include <set>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/json.hpp"
#include "skelgraph/msg/schema.hpp"
#include "skelgraph/recording/merge.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::recording {

nlohmann::json recording_info(const std::string& file) {
  const mcap::Reader reader(file);
  std::string problem;
  try {
    reader.validate();
  } catch (const mcap::McapError& e) {
    problem = e.what();
  }
  const auto s = reader.summary();
  // Ticks and sessions from the sync topic.
  std::uint64_t ticks = 0;
  std::set<std::uint32_t> sessions;
  std::map<std::string, std::uint64_t> per_sensor, ticks_with;
  AckTally acks;
  std::uint64_t tick_records = 0, older_skeletons = 0;
  std::map<std::string, nlohmann::json> clocks;
  reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
    if (schema == nullptr) return;
    if (schema->name == msg::MessageTraits<msg::SyncAck>::name) {
      acks.ack(msg::from_cdr<msg::SyncAck>(m.data.data(), m.data.size()));
    } else if (schema->name == msg::MessageTraits<msg::ClockOffset>::name) {
      const auto c = msg::from_cdr<msg::ClockOffset>(m.data.data(), m.data.size());
      clocks[c.host().to_string()] = nlohmann::json(c);
    }
    if (ch.topic == runtime::topics::kSync.name && schema->name == msg::MessageTraits<msg::SyncCommand>::name) {
      const auto c = msg::from_cdr<msg::SyncCommand>(m.data.data(), m.data.size());
      if (c.kind() == msg::SYNC_TICK) ++ticks;
      sessions.insert(c.session_id());
      acks.session(c.session_id());
    } else if (schema->name == msg::MessageTraits<msg::Skeleton>::name) {
      const auto k = msg::from_cdr<msg::Skeleton>(m.data.data(), m.data.size());
      ++per_sensor[ch.topic + " " + k.sensor_id().to_string()];
      if (msg::may_be_older_schema(schema->name, schema->data)) ++older_skeletons;
    } else if (schema->name == msg::MessageTraits<msg::TickFrames>::name) {
      const auto t = msg::from_cdr<msg::TickFrames>(m.data.data(), m.data.size());
      ++tick_records;
      std::set<std::string> streams;  // a sensor counts once per tick, however many people it saw
      for (const auto& f : t.frames()) streams.insert(f.topic().to_string() + " " + f.sensor_id().to_string());
      for (const auto& k : streams) ++ticks_with[k];
    }
  });
  const double duration =
      s.message_count > 1 ? static_cast<double>(s.message_end_time - s.message_start_time) * 1e-9 : 0.0;
  nlohmann::json topics = nlohmann::json::array();
  for (const auto& [id, ch] : s.channels) {
    const auto count = s.channel_message_counts.count(id) ? s.channel_message_counts.at(id) : 0;
    const auto it = ch.metadata.find("dds_type");
    topics.push_back({{"topic", ch.topic},
                      {"type", it != ch.metadata.end() ? it->second : ""},
                      {"count", count},
                      {"rate_hz", duration > 0 ? static_cast<double>(count) / duration : 0.0}});
  }
  nlohmann::json metadata = nlohmann::json::array();
  for (const auto& m : s.metadata) metadata.push_back({{"name", m.name}, {"values", m.values}});
  // Indexes are optional (the MCAP specification): what is missing was read by scanning. Information, not a defect.
  nlohmann::json notes = nlohmann::json::array();
  if (!s.indexed) notes.push_back("no summary section: everything read by scanning the data section");
  if (s.indexed && !s.has_statistics) notes.push_back("no statistics record: counts from scanning");
  if (s.chunk_count > 0 && !s.has_chunk_indexes) notes.push_back("no chunk indexes: chunks found by scanning");
  if (s.chunk_count > 0 && !s.has_message_indexes) notes.push_back("no message indexes: chunks read whole");
  if (s.attachment_count > 0 && !s.has_attachment_indexes) notes.push_back("no attachment index: attachments found by scanning");
  if (!s.metadata.empty() && !s.has_metadata_indexes) notes.push_back("no metadata index: metadata found by scanning");
  if (older_skeletons > 0) {
    notes.push_back(std::to_string(older_skeletons) +
                    " skeletons in schema 1 (recorded before capture stamps and covariance were on the wire): read "
                    "with capture stamps = stamp_ns and no covariance; bag merge rewrites them in the current schema");
  }
  const nlohmann::json out{{"file", file},
                           {"valid", problem.empty()},
                           {"problem", problem},
                           {"size_bytes", reader.size()},
                           {"library", s.library},
                           {"messages", s.message_count},
                           {"chunks", s.chunk_count},
                           {"attachments", s.attachment_count},
                           {"indexes",
                            {{"summary", s.indexed},
                             {"statistics", s.has_statistics},
                             {"chunk", s.has_chunk_indexes},
                             {"message", s.has_message_indexes},
                             {"attachment", s.has_attachment_indexes},
                             {"metadata", s.has_metadata_indexes},
                             {"summary_offsets", s.has_summary_offsets}}},
                           {"notes", notes},
                           {"start_ns", s.message_start_time},
                           {"end_ns", s.message_end_time},
                           {"duration_s", duration},
                           {"ticks", ticks},
                           {"sessions", sessions},
                           {"topics", topics},
                           {"skeletons_per_sensor", per_sensor},
                           {"skeletons_older_schema", older_skeletons},
                           {"ticks_acked_by_host", acks.by_host()},
                           {"tick_records", tick_records},
                           {"ticks_with_frames_of", ticks_with},
                           {"clock_offsets", clocks},
                           {"metadata", metadata}};
  return out;
}

}  // namespace skelgraph::recording
