#include "skelgraph/runtime/play_gate.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace skelgraph::runtime {

namespace {
bool valid_speed(double s) { return std::isfinite(s) && s >= 0.0 && s <= 1000.0; }
}  // namespace

PlayGate::PlayGate(double speed, bool paused) : speed_(speed), paused_(paused) {
  if (!valid_speed(speed)) throw std::invalid_argument("play: speed must be between 0 and 1000");
}

std::string PlayGate::apply(Kind kind, double value) {
  switch (kind) {
    case Kind::Pause:
      paused_ = true;
      steps_ = 0;
      return "";
    case Kind::Resume:
      paused_ = false;
      steps_ = 0;
      repace_ = true;
      return "";
    case Kind::Step:
      if (!std::isfinite(value) || value < 1.0 || value > 1e6 || value != std::floor(value)) {
        return "step: frames must be a whole number from 1 to 1000000";
      }
      paused_ = true;
      steps_ += static_cast<std::uint64_t>(value);
      repace_ = true;
      return "";
    case Kind::Speed:
      if (!valid_speed(value)) return "speed must be between 0 and 1000 (0: as fast as frames can be read)";
      speed_ = value;
      repace_ = true;
      return "";
    case Kind::Seek:
      if (!std::isfinite(value) || value < 0.0) return "seek: the position must be 0 or more seconds";
      seek_ = value;
      repace_ = true;
      return "";
  }
  return "unknown request";
}

bool PlayGate::delivered(bool stepped) {
  if (!stepped || !paused_ || steps_ == 0) return false;
  return --steps_ == 0;
}

std::optional<double> PlayGate::take_seek() { return std::exchange(seek_, std::nullopt); }

bool PlayGate::take_repace() {
  const bool r = repace_;
  repace_ = false;
  return r;
}

}  // namespace skelgraph::runtime
