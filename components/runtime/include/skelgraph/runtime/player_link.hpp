#pragma once
// A player of a recording on the graph (openni2 on an .oni file, bag_player on
// an MCAP file): takes the requests on skelgraph/play/control meant for it
// (target "" or its name; each request id once: requesters repeat a request
// until it is answered), applies them to its PlayGate and answers on
// skelgraph/play/state. A step is answered once its frames are out, a seek
// once the player is at the new position (so the answer, and any state read
// after it, carries that position).
//
// Thread-safe: requests arrive on the executor; the player's own thread reads
// the gate through with_gate() and reports delivered frames.

#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/play_gate.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::runtime {

class PlayerLink {
 public:
  struct Progress {
    std::uint64_t frames = 0;       // delivered since start
    std::int64_t frame_count = -1;  // in the recording, -1 unknown
    bool at_end = false;
    double position_s = -1.0;       // seconds from the recording's start, -1 unknown
    double duration_s = -1.0;
  };
  // `progress` is called without the link's lock held; `can_seek` false refuses seeks.
  PlayerLink(Context& ctx, PlayGate gate, std::function<Progress()> progress, bool can_seek);

  // What the player may do now, read under the lock: deliver a frame (not
  // paused, or steps left), pace afresh (after resume, speed, step, seek),
  // stepping (paused with steps: no waiting), at which speed.
  struct Turn {
    bool deliver = false, repace = false, stepping = false;
    double speed = 1.0;
  };
  Turn turn();

  template <class F>
  auto with_gate(F&& f) {
    std::lock_guard<std::mutex> lock(mutex_);
    return f(gate_);
  }
  // Waits until a request arrives or `timeout` passes (a paused player's sleep).
  void wait_for_request(std::chrono::nanoseconds timeout);
  // After each delivered frame (`stepped`: its turn said stepping): answers a
  // step request whose frames are out.
  void delivered(bool stepped);
  // At the end of the recording: answers a step request that cannot finish.
  void at_end();
  // After the player has gone to a seek's position: answers the seek requests taken.
  void sought();
  void publish_state(const std::string& request_id = "", const std::string& error = "");

 private:
  void on_request(const msg::PlayControl& c);

  Context& ctx_;
  std::function<Progress()> progress_;
  bool can_seek_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::uint64_t requests_ = 0;
  PlayGate gate_;
  std::deque<std::string> handled_;  // the latest request ids
  std::string step_request_;         // answered when its steps are delivered
  std::vector<std::string> seek_requests_;  // answered when the player is at the position (the latest seek wins)
  Publisher<msg::PlayState> state_pub_;
  Subscription<msg::PlayControl> control_sub_;
};

}  // namespace skelgraph::runtime
