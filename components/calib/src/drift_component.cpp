// `drift` component: watches whether a sensor has been knocked out of place
// since it was calibrated (calib::DriftMonitor on the raw skeletons and the
// poses on skelgraph/calibration). A sensor that drifted makes it DEGRADED,
// named with how far off it places the person; with `refine` it instead
// publishes that sensor's pose corrected by what the others see (fusion
// takes it up like any calibration), says so and watches the new pose.

#include <algorithm>
#include <mutex>
#include <set>
#include <sstream>

#include "skelgraph/calib/drift.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/registry.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::calib {

namespace {
DriftOptions options_from(const runtime::Params& p) {
  DriftOptions o;
  o.window_s = p.get<double>("window_s");
  o.settle_s = p.get<double>("settle_s");
  o.alarm_cm = p.get<double>("alarm_cm");
  o.confirm = static_cast<int>(p.get<std::int64_t>("confirm"));
  return o;
}
}  // namespace

class DriftComponent final : public runtime::Component {
 public:
  DriftComponent(runtime::Context& ctx, const runtime::Params& params)
      : Component(ctx),
        monitor_(options_from(params)),
        refine_(params.get<bool>("refine")),
        raw_sub_(ctx, runtime::topics::kSkeletonRaw,
                 [this](const msg::Skeleton& m, const runtime::SampleMeta& meta) {
                   const auto s = skeleton::from_msg(m);
                   std::lock_guard<std::mutex> lock(mutex_);
                   monitor_.add(s.sensor_id, meta.receive_ns, s);
                 }),
        pose_sub_(ctx, runtime::topics::kCalibration,
                  [this](const msg::SensorPose& m, const runtime::SampleMeta&) {
                    const auto p = skeleton::from_msg(m);
                    if (p.frame_id != "world") return;
                    std::lock_guard<std::mutex> lock(mutex_);
                    monitor_.set_pose(p.sensor_id, p.pose);
                  }),
        pose_pub_(ctx, runtime::topics::kCalibration) {}

  static runtime::ComponentInfo describe() {
    runtime::ComponentInfo info{"drift",
                                "Reports a sensor knocked out of place since its calibration (the sensors' skeletons no "
                                "longer agree as they did), and with refine publishes its corrected pose",
                                {}};
    info.params.add_double("window_s", 10.0, "each check takes this much of the sensors' skeletons, s", 1.0, 120.0)
        .add_double("settle_s", 20.0, "the first this much of each pair's shared views is its baseline, s", 1.0, 600.0)
        .add_double("alarm_cm", 4.5, "a pair whose offset at the person moved this much from its baseline is off, cm", 0.5, 100.0)
        .add_int("confirm", 3, "checks in a row (one a second) a pair must be off", 1, 60)
        .add_bool("refine", false, "publish a drifted sensor's corrected pose on skelgraph/calibration");
    return info;
  }

  void on_start() override {
    ctx_.set_health(runtime::HealthState::Ok, "waiting for sensor poses and skeletons");
    timer_ = ctx_.executor().every(std::chrono::seconds(1), [this] { check(); });
  }

  std::string summary() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    return message_;
  }
  nlohmann::json details() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    nlohmann::json sensors = nlohmann::json::array(), pairs = nlohmann::json::array();
    for (const auto& s : monitor_.sensors()) {
      sensors.push_back({{"sensor", s.id}, {"drifted", s.drifted}, {"shift_cm", s.shift_cm}, {"since_ns", s.since_ns}});
    }
    for (const auto& p : monitor_.pairs()) {
      pairs.push_back({{"a", p.a}, {"b", p.b}, {"baseline", p.has_baseline}, {"evaluated", p.evaluated}, {"joint_pairs", p.pairs},
                       {"shift_cm", p.shift_cm}, {"change_m", {p.change.x(), p.change.y(), p.change.z()}}});
    }
    return {{"sensors", sensors}, {"pairs", pairs},         {"reports", reports_},
            {"refined", refined_}, {"refinements", details_}, {"failed_writes", failed_}};
  }

 private:
  void check() {
    std::vector<SensorDrift> drifted;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      monitor_.update(ctx_.clock().now_ns());
      std::size_t watched = 0;
      for (const auto& s : monitor_.sensors()) {
        ++watched;
        if (s.drifted) drifted.push_back(s);
      }
      std::ostringstream os;
      if (drifted.empty()) {
        std::size_t baselines = 0;
        for (const auto& p : monitor_.pairs()) baselines += p.has_baseline ? 1 : 0;
        os << watched << " sensor(s) watched, " << baselines << " pair(s) with a baseline; none moved";
      } else {
        for (const auto& s : drifted) {
          if (!reported_.count(s.id)) ++reports_, reported_.insert(s.id);
          os << (os.tellp() > 0 ? "; " : "") << s.id << " moved since its calibration: it places the person " << std::fixed;
          os.precision(1);
          os << s.shift_cm << " cm from where the other sensors do, beyond their usual disagreement";
        }
        if (drifted.size() == 2 && watched == 2) os << " (two sensors cannot tell which one moved)";
      }
      if (!refinements_.empty()) os << "; refined " << refinements_;
      for (auto it = reported_.begin(); it != reported_.end();) {
        const bool still = std::any_of(drifted.begin(), drifted.end(), [&](const SensorDrift& s) { return s.id == *it; });
        it = still ? std::next(it) : reported_.erase(it);
      }
      message_ = os.str();
    }
    // Refined: one sensor (with two, which one moved is not known). Its new
    // pose comes back on skelgraph/calibration and restarts its baselines.
    bool failed = false, refined = false;
    if (refine_ && drifted.size() == 1) {
      skeleton::SensorPose p;
      p.sensor_id = drifted.front().id;
      p.pose = drifted.front().refined;
      p.method = "drift refined";
      p.stamp_ns = ctx_.clock().now_ns();
      refined = pose_pub_.publish(skeleton::to_msg(p));
      failed = !refined;
      std::lock_guard<std::mutex> lock(mutex_);
      if (refined) {
        ++refined_;
        std::ostringstream os;
        os.precision(1);
        os << std::fixed << (refinements_.empty() ? "" : ", ") << p.sensor_id << " (it placed the person "
           << drifted.front().shift_cm << " cm off)";
        refinements_ += os.str();
        details_.push_back({{"sensor", p.sensor_id}, {"shift_cm", drifted.front().shift_cm}, {"at_ns", p.stamp_ns}});
        message_ = "refined " + refinements_;
      } else {
        ++failed_;
      }
    }
    if (failed) {
      ctx_.set_health(runtime::HealthState::Degraded, "could not publish a refined pose; " + message_);
    } else {
      ctx_.set_health(drifted.empty() || refined ? runtime::HealthState::Ok : runtime::HealthState::Degraded, message_);
    }
  }

  mutable std::mutex mutex_;  // the monitor: DDS callbacks, the executor, reports from the launcher's thread
  DriftMonitor monitor_;
  bool refine_;
  std::string message_ = "starting";
  std::string refinements_;                 // "sensor2 (it placed the person 10.3 cm off), ..."
  nlohmann::json details_ = nlohmann::json::array();
  std::set<std::string> reported_;
  std::size_t reports_ = 0, refined_ = 0, failed_ = 0;
  runtime::Subscription<msg::Skeleton> raw_sub_;
  runtime::Subscription<msg::SensorPose> pose_sub_;
  runtime::Publisher<msg::SensorPose> pose_pub_;
  runtime::TimerHandle timer_;
};

}  // namespace skelgraph::calib

SKELGRAPH_REGISTER_COMPONENT(drift, skelgraph::calib::DriftComponent)
