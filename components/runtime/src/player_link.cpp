#include "skelgraph/runtime/player_link.hpp"

#include <algorithm>
#include <utility>

namespace skelgraph::runtime {

PlayerLink::PlayerLink(Context& ctx, PlayGate gate, std::function<Progress()> progress, bool can_seek)
    : ctx_(ctx),
      progress_(std::move(progress)),
      can_seek_(can_seek),
      gate_(gate),
      state_pub_(ctx, topics::kPlayState),
      control_sub_(ctx, topics::kPlayControl,
                   [this](const msg::PlayControl& c, const SampleMeta&) { on_request(c); }) {}

void PlayerLink::on_request(const msg::PlayControl& c) {
  const std::string target = c.target().to_string(), id = c.request_id().to_string();
  if (!target.empty() && target != ctx_.name()) return;
  std::string error;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!id.empty()) {
      if (std::find(handled_.begin(), handled_.end(), id) != handled_.end()) return;
      handled_.push_back(id);
      if (handled_.size() > 32) handled_.pop_front();
    }
    using K = PlayGate::Kind;
    K kind = K::Pause;
    switch (c.kind()) {
      case msg::PLAY_PAUSE: kind = K::Pause; break;
      case msg::PLAY_RESUME: kind = K::Resume; break;
      case msg::PLAY_STEP: kind = K::Step; break;
      case msg::PLAY_SPEED: kind = K::Speed; break;
      case msg::PLAY_SEEK: kind = K::Seek; break;
      default: error = "unknown request kind " + std::to_string(static_cast<int>(c.kind()));
    }
    if (error.empty() && kind == K::Seek && !can_seek_) error = "seek: this player cannot seek";
    if (error.empty()) error = gate_.apply(kind, c.value());
    ++requests_;
    cv_.notify_all();
    if (error.empty() && kind == K::Step) {
      step_request_ = id;  // answered once the frames are out
      return;
    }
    if (error.empty() && kind == K::Seek) {
      seek_requests_.push_back(id);  // answered once the player is there
      return;
    }
  }
  publish_state(id, error);
}

PlayerLink::Turn PlayerLink::turn() {
  std::lock_guard<std::mutex> lock(mutex_);
  return Turn{gate_.may_deliver(), gate_.take_repace(), gate_.paused(), gate_.speed()};
}

void PlayerLink::wait_for_request(std::chrono::nanoseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto seen = requests_;
  cv_.wait_for(lock, timeout, [&] { return requests_ != seen; });
}

void PlayerLink::delivered(bool stepped) {
  std::string answer;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (gate_.delivered(stepped)) answer = std::exchange(step_request_, "");
  }
  if (!answer.empty()) publish_state(answer, "");
}

void PlayerLink::at_end() {
  std::string pending;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending = std::exchange(step_request_, "");
  }
  publish_state(pending, pending.empty() ? "" : "the recording ended before the steps were done");
}

void PlayerLink::sought() {
  std::vector<std::string> answered;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    answered.swap(seek_requests_);
  }
  if (answered.empty()) publish_state();
  for (const auto& id : answered) publish_state(id, "");
}

void PlayerLink::publish_state(const std::string& request_id, const std::string& error) {
  const Progress p = progress_();
  msg::PlayState s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.paused(gate_.paused());
    s.speed(gate_.speed());
  }
  s.player(ctx_.name().substr(0, 64));
  s.frames(p.frames);
  s.frame_count(p.frame_count);
  s.at_end(p.at_end);
  s.position_s(p.position_s);
  s.duration_s(p.duration_s);
  s.request_id(request_id.substr(0, 64));
  s.error(error.substr(0, 128));
  state_pub_.publish(s);
}

}  // namespace skelgraph::runtime
