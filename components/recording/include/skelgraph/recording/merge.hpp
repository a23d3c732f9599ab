#pragma once
// Several hosts' recordings of one session onto the sync master's timeline
// (`skelgraph bag merge`): each file's log times are corrected by its host's
// clock offset (the latest skelgraph/sync/clock estimate found in any input,
// drift included); a message recorded by several hosts (same topic, same
// bytes, within `duplicate_window_s` of each other) is kept once, repeats
// within one recording are kept; older schemas are written in the current
// one; every sync tick gets a TickFrames record on skelgraph/sync/tick_frames.
//
// Streaming, in bounded memory: the inputs are read twice (hosts, clock
// offsets and acks first; then the messages), a reader thread per input feeds
// a bounded queue, and the one time-ordered queue (runtime::OrderedQueue)
// interleaves them; what is held at once is about `reorder_s` of every input
// plus the duplicate window's hashes, whatever the recordings' sizes.

#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/messages.hpp"

namespace skelgraph::recording {

// Ticks acked per host: distinct ticks of the recording's sessions (the
// sessions its sync topic names). An ack of the previous session's last tick
// can arrive after the next session's file was opened; it is not counted.
class AckTally {
 public:
  void ack(const msg::SyncAck& a) { acks_.insert({a.host().to_string(), a.session_id(), a.tick()}); }
  void session(std::uint32_t id) { sessions_.insert(id); }
  std::map<std::string, std::uint64_t> by_host() const {
    std::map<std::string, std::uint64_t> out;
    for (const auto& [host, session, tick] : acks_) {
      if (sessions_.count(session)) ++out[host];
    }
    return out;
  }

 private:
  std::set<std::tuple<std::string, std::uint32_t, std::uint64_t>> acks_;
  std::set<std::uint32_t> sessions_;
};

// An input that cannot be merged (no session metadata naming its host).
class MergeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MergeOptions {
  mcap::Compression compression = mcap::Compression::Zstd;
  double max_age_ms = 100.0;          // a frame older than this at a tick is not associated with it
  double reorder_s = 1.0;             // a recording's messages this far out of log-time order still come out in order
  double duplicate_window_s = 10.0;   // the same message from two hosts this far apart (corrected) is one
  std::size_t queue_bytes = 4u << 20;  // message bytes each reader thread may hold ready
};

struct MergeInput {
  std::string file, host;
  double offset_ns = 0, drift_ppm = 0;
  bool estimated = false;  // a clock estimate for its host was found
};

struct MergeReport {
  std::string out;
  std::uint64_t messages = 0;  // written, tick records included
  std::uint64_t duplicates_dropped = 0;
  std::uint64_t tick_records = 0, frames_at_ticks = 0;
  std::uint64_t out_of_order = 0;  // later than reorder_s behind its input's newest: written late, counted
  std::vector<MergeInput> inputs;
  std::map<std::string, std::uint64_t> ticks_acked_by_host;
  std::size_t peak_held = 0;  // most messages held in the ordered queue at once
};

// Throws MergeError (an input without its host), mcap::McapError (an unreadable input).
MergeReport merge_recordings(const std::vector<std::string>& files, const std::string& out_path,
                             const MergeOptions& options = {});

}  // namespace skelgraph::recording
