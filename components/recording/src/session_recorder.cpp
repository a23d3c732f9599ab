#include "skelgraph/recording/session_recorder.hpp"

#include <filesystem>
#include <system_error>

namespace skelgraph::recording {

std::string file_safe(std::string s) {
  for (auto& c : s) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
  }
  return s.empty() ? "_" : s;
}

std::string SessionRecorder::file_name(const std::string& label, std::uint32_t session_id, const std::string& host) {
  return file_safe(label) + "_" + std::to_string(session_id) + "_" + file_safe(host) + ".mcap";
}

SessionRecorder::SessionRecorder(const RecorderOptions& options, const std::string& label, std::uint32_t session_id,
                                 std::int64_t now_ns)
    : opt_(options), label_(label), session_(session_id), started_ns_(now_ns), last_flush_ns_(now_ns) {
  std::error_code ec;
  std::filesystem::create_directories(opt_.directory, ec);
  if (ec) throw mcap::McapError("cannot create recording directory " + opt_.directory + ": " + ec.message());
  // A recorder restarted within a session (its process, or its participant
  // after a stuck authentication) goes on in a new file: never overwrite.
  const std::filesystem::path dir(opt_.directory);
  const std::string name = file_name(label, session_id, opt_.host);
  path_ = (dir / name).string();
  for (int k = 2; std::filesystem::exists(path_, ec); ++k) {
    path_ = (dir / (name.substr(0, name.size() - 5) + "_" + std::to_string(k) + ".mcap")).string();
  }
  mcap::WriterOptions wo;
  wo.compression = opt_.compression;
  wo.library = "skelgraph recorder";
  bag_ = std::make_unique<BagWriter>(path_, wo);
  bag_->write_metadata("session", {{"label", label_},
                                   {"session_id", std::to_string(session_)},
                                   {"host", opt_.host},
                                   {"started_ns", std::to_string(started_ns_)}});
  bag_->flush();  // the file is valid up to here even if we are killed now
  if (opt_.make_tap) tap_ = opt_.make_tap();
}

SessionRecorder::~SessionRecorder() = default;

void SessionRecorder::record(const std::string& topic, const std::string& type_name, bool keyed, std::string_view cdr,
                             std::int64_t log_ns, std::int64_t publish_ns) {
  std::lock_guard lock(mutex_);
  if (!bag_) return;
  bag_->write_cdr(topic, type_name, keyed, cdr, static_cast<std::uint64_t>(std::max<std::int64_t>(0, log_ns)),
                  static_cast<std::uint64_t>(std::max<std::int64_t>(0, publish_ns)));
  ++counts_[topic];
  ++messages_;
  if (tap_) tap_->add(bag_->mcap(), topic, type_name, cdr, log_ns);
}

void SessionRecorder::maybe_flush(std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  if (!bag_ || now_ns - last_flush_ns_ < opt_.flush_period_ns) return;
  bag_->flush();
  last_flush_ns_ = now_ns;
}

void SessionRecorder::finish(std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  if (!bag_) return;
  mcap::KeyValues stats{{"label", label_},      {"session_id", std::to_string(session_)},
                        {"host", opt_.host},    {"started_ns", std::to_string(started_ns_)},
                        {"stopped_ns", std::to_string(now_ns)}, {"messages", std::to_string(messages_)}};
  if (tap_) tap_->finish(bag_->mcap());
  for (const auto& [topic, n] : counts_) stats["count " + topic] = std::to_string(n);
  bag_->write_metadata("recording", stats);
  bag_->close();
  bag_.reset();
}

std::uint64_t SessionRecorder::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

std::map<std::string, std::uint64_t> SessionRecorder::counts() const {
  std::lock_guard lock(mutex_);
  return counts_;
}

}  // namespace skelgraph::recording
