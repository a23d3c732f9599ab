#pragma once
// How a player of a recording is driven: paused, resumed, stepped frame by
// frame, sped up or slowed down (requests on skelgraph/play/control). Pure
// state, no DDS and no clock: the player asks may_deliver() before each frame
// and reports delivered() after it; it restarts its pacing when
// take_repace() says so.

#include <cstdint>
#include <optional>
#include <string>

namespace skelgraph::runtime {

class PlayGate {
 public:
  enum class Kind { Pause, Resume, Step, Speed, Seek };

  // Throws std::invalid_argument for a negative or non-finite speed.
  explicit PlayGate(double speed = 1.0, bool paused = false);

  // Applies a request. Returns why it is refused ("" when applied): a speed
  // that is negative, not finite or above 1000; a step of fewer than 1 or more
  // than 1000000 frames, or not a whole number; a seek to a negative or not
  // finite position (seconds from the start). A step pauses a running player
  // and lets `value` frames through; pause cancels steps left; a seek keeps
  // the player paused or playing as it was and is taken by take_seek().
  std::string apply(Kind kind, double value = 0.0);
  // Once per seek request: the position asked for (the latest, if several came).
  std::optional<double> take_seek();

  bool may_deliver() const { return !paused_ || steps_ > 0; }
  // After each delivered frame, saying whether it was let through as a step
  // (paused() when the player asked): true when it was the last of a step
  // request. A frame let through before a pause or a step (its player was
  // slow to report it) does not count against the step.
  bool delivered(bool stepped);
  // True once after a change from which pacing starts afresh (resume, speed, step).
  bool take_repace();

  bool paused() const { return paused_; }
  double speed() const { return speed_; }
  std::uint64_t steps_left() const { return steps_; }

 private:
  double speed_;
  bool paused_;
  std::uint64_t steps_ = 0;
  bool repace_ = false;
  std::optional<double> seek_;
};

}  // namespace skelgraph::runtime
