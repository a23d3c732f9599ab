#pragma once
// `gesture` component: spots gestures in a skeleton stream (fused by
// default) with a trained classifier (`skelgraph gesture train` or `gesture
// sim --out`), one Spotter per person, and publishes each on
// skelgraph/gesture/event (for pointing: the ray and where it meets the floor
// or a configured surface) and each person's motion state on
// skelgraph/gesture/state (on change and every second). Every person of
// the stream is watched at once; one whose skeleton instance is disposed
// (they left) is forgotten at once and their state disposed. Events are also
// logged, so `skelgraph launch` prints them.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "skelgraph/gesture/classifier.hpp"
#include "skelgraph/gesture/spotter.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace skelgraph::gesture {

class GestureComponent final : public runtime::Component {
 public:
  GestureComponent(runtime::Context& ctx, const runtime::Params& params);
  static runtime::ComponentInfo describe();
  void on_start() override;
  std::string summary() const override;
  nlohmann::json details() const override;

 private:
  struct Person {
    std::unique_ptr<Spotter> spotter;
    std::int64_t last_seen_ns = 0;
    std::int64_t last_stamp_ns = 0;
    MotionState published = MotionState::Resting;
    bool ever_published = false;
  };
  using People = std::map<std::pair<std::string, std::uint32_t>, Person>;  // (source, person id)
  void on_skeleton(const skeleton::Skeleton& s, std::int64_t receive_ns);
  void publish_state(const std::string& source, std::uint32_t person, const Person& p);
  // The person left: their state instance is disposed.
  People::iterator forget(People::iterator it);

  SpotterOptions options_;  // first: bad parameters are refused before a model is trained
  Classifier classifier_;
  std::int64_t person_timeout_ns_;
  People people_;
  std::map<std::string, std::uint64_t> events_by_label_;
  std::uint64_t skeletons_ = 0, events_ = 0, seen_ = 0, left_ = 0;
  runtime::Publisher<msg::GestureEvent> event_pub_;
  runtime::Publisher<msg::GestureState> state_pub_;
  runtime::Subscription<msg::Skeleton> sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::gesture
