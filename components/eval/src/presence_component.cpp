// `presence` component: listens to the cell (ground truth, raw and fused
// skeletons, sensor poses, every component's status, and the instances
// their writers dispose) and measures, with eval::Presence, whether everyone
// in the cell is shown, whether departures are seen, and whether writers fail
// or keep instances of people who left. Its report is the JSON `details`
// (`skelgraph launch --json`, `skelgraph eval presence`).

#include <mutex>
#include <sstream>

#include "skelgraph/eval/presence.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/registry.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::eval {

namespace {
PresenceOptions options_from(const runtime::Params& p) {
  PresenceOptions o;
  o.match_m = p.get<double>("match_m");
  o.departure_limit_ns = static_cast<std::int64_t>(p.get<double>("departure_limit_s") * 1e9);
  o.linger_ns = static_cast<std::int64_t>(p.get<double>("linger_s") * 1e9);
  return o;
}
}  // namespace

class PresenceComponent final : public runtime::Component {
 public:
  PresenceComponent(runtime::Context& ctx, const runtime::Params& params)
      : Component(ctx),
        core_(options_from(params)),
        people_(params.get<bool>("people")),
        truth_sub_(
            ctx, runtime::topics::kSkeletonTruth,
            [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) { with([&] { core_.truth(skeleton::from_msg(m), meta.receive_ns); }); },
            [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) { with([&] { core_.truth_gone(m.person_id(), meta.receive_ns); }); }),
        raw_sub_(
            ctx, runtime::topics::kSkeletonRaw,
            [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) { with([&] { core_.raw(skeleton::from_msg(m), meta.receive_ns); }); },
            [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
              with([&] { core_.raw_gone(m.sensor_id().to_string(), m.person_id(), meta.receive_ns); });
            }),
        fused_sub_(
            ctx, runtime::topics::kSkeletonFused,
            [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) { with([&] { core_.fused(skeleton::from_msg(m), meta.receive_ns); }); },
            [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
              with([&] { core_.fused_gone(m.sensor_id().to_string(), m.person_id(), meta.receive_ns); });
            }),
        pose_sub_(ctx, runtime::topics::kCalibration,
                  [this](const msg::SensorPose& m, const runtime::SampleMeta&) {
                    const auto p = skeleton::from_msg(m);
                    if (p.frame_id == "world") with([&] { core_.pose(p.sensor_id, p.pose); });
                  }),
        status_sub_(ctx, runtime::topics::kStatus, [this](const msg::ComponentStatus& s, const runtime::SampleMeta& meta) {
          with([&] {
            for (const auto& t : s.topics()) {
              if (t.is_output()) core_.output(s.component_name().to_string(), t.topic().to_string(), t.dropped(), t.instances(), meta.receive_ns);
            }
          });
        }) {}

  static runtime::ComponentInfo describe() {
    runtime::ComponentInfo info{"presence",
                                "Measures who is in the cell (ground truth) against who the graph shows: completeness per "
                                "person, departures seen, failed writes, live instances against the people there",
                                {}};
    info.params.add_double("match_m", 0.5, "torsos this close (horizontally) are the same person", 0.05, 5.0)
        .add_double("departure_limit_s", 1.0, "a fused departure seen later than this after its inputs' counts as late", 0.01, 60.0)
        .add_double("linger_s", 3.0, "people who left this recently still count for the instance bounds (a tracker's ghost)", 0.0, 60.0)
        .add_bool("people", false, "list every person in the report");
    return info;
  }

  void on_start() override {
    timer_ = ctx_.executor().every(std::chrono::milliseconds(100), [this] {
      const auto now = ctx_.clock().now_ns();
      with([&] { core_.sample(now); });
    });
  }

  std::string summary() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto r = core_.report();
    std::ostringstream os;
    os << r["people"]["seen"] << " people seen, " << r["people"]["left"] << " left; shown "
       << static_cast<int>(100.0 * r["completeness"]["shown_of_tracked"].get<double>()) << " % of the time tracked; "
       << r["departures"]["seen"] << " of " << r["departures"]["people"] << " departures seen ("
       << r["departures"]["late"] << " late); " << r["failed_writes"] << " failed write(s)";
    return os.str();
  }
  nlohmann::json details() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    return core_.report(people_);
  }

 private:
  template <class F>
  void with(F&& f) {
    std::lock_guard<std::mutex> lock(mutex_);
    f();
  }

  mutable std::mutex mutex_;  // the core: executor thread, and reports from the launcher's
  Presence core_;
  bool people_;
  runtime::Subscription<msg::Skeleton> truth_sub_, raw_sub_, fused_sub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Subscription<msg::ComponentStatus> status_sub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::eval

SKELGRAPH_REGISTER_COMPONENT(presence, skelgraph::eval::PresenceComponent)
