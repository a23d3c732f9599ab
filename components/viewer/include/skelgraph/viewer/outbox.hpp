#pragma once
// What waits to be sent to one viewer client. Frames are the latest only: a
// client that reads slower than frames are made gets the newest frame when it
// is ready and the ones in between are dropped (counted), so nothing queues
// without bound and no client lags behind the graph. Replies to the client's
// own requests are few; at most `max_replies` wait (the oldest go first).
// Not thread-safe: one per client, used on the server's thread.

#include <cstdint>
#include <deque>
#include <memory>
#include <string>

namespace skelgraph::viewer {

class Outbox {
 public:
  using Message = std::shared_ptr<const std::string>;
  explicit Outbox(std::size_t max_replies = 16) : max_replies_(max_replies) {}

  void push_frame(Message m) {
    if (frame_) ++dropped_frames_;
    frame_ = std::move(m);
  }
  void push_reply(Message m) {
    if (replies_.size() >= max_replies_) {
      replies_.pop_front();
      ++dropped_replies_;
    }
    replies_.push_back(std::move(m));
  }
  // The next message to write (replies first), or null when there is none.
  Message take() {
    if (!replies_.empty()) {
      auto m = std::move(replies_.front());
      replies_.pop_front();
      return m;
    }
    return std::move(frame_);  // leaves frame_ empty
  }
  bool empty() const { return replies_.empty() && !frame_; }
  std::uint64_t dropped_frames() const { return dropped_frames_; }
  std::uint64_t dropped_replies() const { return dropped_replies_; }

 private:
  std::size_t max_replies_;
  std::deque<Message> replies_;
  Message frame_;
  std::uint64_t dropped_frames_ = 0, dropped_replies_ = 0;
};

}  // namespace skelgraph::viewer
