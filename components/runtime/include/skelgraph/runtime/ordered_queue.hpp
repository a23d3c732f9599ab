#pragma once
// The one time-ordered queue (after Cartographer's OrderedMultiQueue): items
// of several streams come out in time order (ties: in the order they were
// pushed), each as soon as no stream can still bring an earlier one. A
// stream's items arrive in its own time order up to `lateness_ns` (a
// recording's messages a little out of log-time order); until a stream has
// pushed something, or is finished, it holds everything back, and blocker()
// says which stream that is (the one to read next). Memory: what the slowest
// stream's lateness and the streams' differences in progress hold back.
//
// Serves the offline readers of recordings (eval, fuse), the bag player and
// merge. DDS-free, no clock: times are whatever the caller orders by.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <queue>
#include <stdexcept>
#include <utility>
#include <vector>

namespace skelgraph::runtime {

template <class T, class StreamId = std::size_t>
class OrderedQueue {
 public:
  // Declares a stream (before its first push; a stream pushed to without
  // being declared gets lateness 0).
  void add_stream(const StreamId& id, std::int64_t lateness_ns = 0) {
    if (streams_.count(id)) throw std::logic_error("OrderedQueue: stream added twice");
    streams_[id].lateness_ns = lateness_ns;
  }

  void push(const StreamId& id, std::int64_t t_ns, T item) {
    auto& s = streams_[id];
    if (s.finished) throw std::logic_error("OrderedQueue: push to a finished stream");
    s.newest_ns = s.any ? std::max(s.newest_ns, t_ns) : t_ns;
    s.any = true;
    held_.push({t_ns, seq_++, std::move(item)});
  }

  // The stream will push nothing more: it no longer holds anything back.
  void finish(const StreamId& id) { streams_[id].finished = true; }

  // Hands `f(t_ns, T&&)` every item no stream can still precede, in order.
  template <class F>
  void drain(F&& f) {
    const auto until = release_until();
    while (!held_.empty() && held_.top().t_ns <= until) pop_into(f);
  }

  // Everything held, in order (the end of all input).
  template <class F>
  void flush(F&& f) {
    while (!held_.empty()) pop_into(f);
  }

  // The unfinished stream that holds the queue back (nothing pushed yet, or
  // the least advanced); empty when none does.
  std::optional<StreamId> blocker() const {
    std::optional<StreamId> who;
    std::int64_t least = std::numeric_limits<std::int64_t>::max();
    for (const auto& [id, s] : streams_) {
      if (s.finished) continue;
      if (!s.any) return id;
      if (s.newest_ns - s.lateness_ns < least) {
        least = s.newest_ns - s.lateness_ns;
        who = id;
      }
    }
    return who;
  }

  std::size_t size() const { return held_.size(); }
  bool empty() const { return held_.empty(); }

 private:
  struct Stream {
    std::int64_t lateness_ns = 0;
    std::int64_t newest_ns = 0;
    bool any = false, finished = false;
  };
  struct Held {
    std::int64_t t_ns;
    std::uint64_t seq;
    T item;
  };
  struct Later {
    bool operator()(const Held& a, const Held& b) const { return a.t_ns != b.t_ns ? a.t_ns > b.t_ns : a.seq > b.seq; }
  };

  // Items at or before this time can go: every unfinished stream has pushed
  // something after it (allowing for the stream's lateness).
  std::int64_t release_until() const {
    std::int64_t until = std::numeric_limits<std::int64_t>::max();
    for (const auto& [id, s] : streams_) {
      if (s.finished) continue;
      if (!s.any) return std::numeric_limits<std::int64_t>::min();
      until = std::min(until, s.newest_ns - s.lateness_ns);
    }
    return until;
  }

  template <class F>
  void pop_into(F& f) {
    // (The top is const in a priority_queue; its item is moved out just before it goes.)
    auto& top = const_cast<Held&>(held_.top());
    const auto t = top.t_ns;
    T item = std::move(top.item);
    held_.pop();
    f(t, std::move(item));
  }

  std::map<StreamId, Stream> streams_;
  std::priority_queue<Held, std::vector<Held>, Later> held_;
  std::uint64_t seq_ = 0;
};

}  // namespace skelgraph::runtime
