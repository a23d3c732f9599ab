#pragma once
// One recording session on one host: an MCAP file named after the session
// (label, id, host), every sample recorded as it arrived, flushed at least
// every `flush_period_ns` so a killed recorder loses at most that much.
// Thread-safe (DDS delivers samples from several threads). No DDS here.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "skelgraph/recording/bag.hpp"

namespace skelgraph::recording {

// `s` with anything but [A-Za-z0-9._-] replaced by '_' (file names from labels, hosts, sensor ids).
std::string file_safe(std::string s);

// Writes more into a session's file as its samples are recorded (the 3-D
// scene: skelgraph::scene::SceneTap); called under the recorder's lock, in
// arrival order.
class RecordTap {
 public:
  virtual ~RecordTap() = default;
  virtual void add(mcap::Writer& w, const std::string& topic, const std::string& type_name, std::string_view cdr,
                   std::int64_t log_ns) = 0;
  virtual void finish(mcap::Writer& w) = 0;  // before the file is closed
};

struct RecorderOptions {
  std::function<std::unique_ptr<RecordTap>()> make_tap;  // one per file, if given
  std::string directory = "recordings";
  std::string host;                                   // goes into the file name and metadata
  mcap::Compression compression = mcap::Compression::Zstd;
  std::int64_t flush_period_ns = 1'000'000'000;
};

class SessionRecorder {
 public:
  // Creates the directory and the file; throws McapError saying why not
  // (unwritable path, full disk, ...).
  SessionRecorder(const RecorderOptions& options, const std::string& label, std::uint32_t session_id,
                  std::int64_t now_ns);
  ~SessionRecorder();

  // File name: <label>_<session>_<host>.mcap, anything but [A-Za-z0-9._-] replaced by '_'.
  // If that file exists (the recorder was restarted within the session), the
  // new one is <label>_<session>_<host>_2.mcap, _3, ...: nothing is overwritten.
  static std::string file_name(const std::string& label, std::uint32_t session_id, const std::string& host);

  void record(const std::string& topic, const std::string& type_name, bool keyed, std::string_view cdr,
              std::int64_t log_ns, std::int64_t publish_ns);
  // Flushes when the period has passed since the last flush.
  void maybe_flush(std::int64_t now_ns);
  // Writes the session's metadata and closes the file.
  void finish(std::int64_t now_ns);

  const std::string& path() const { return path_; }
  std::uint64_t messages() const;
  std::map<std::string, std::uint64_t> counts() const;  // per topic

 private:
  mutable std::mutex mutex_;
  RecorderOptions opt_;
  std::string label_, path_;
  std::uint32_t session_;
  std::int64_t started_ns_, last_flush_ns_;
  std::unique_ptr<BagWriter> bag_;
  std::unique_ptr<RecordTap> tap_;
  std::map<std::string, std::uint64_t> counts_;
  std::uint64_t messages_ = 0;
};

}  // namespace skelgraph::recording
