// `calibration` component: publishes the sensor poses of a calibration file
// on skelgraph/calibration (reliable, transient-local: fusion started later
// still gets them). A bad file fails the graph's start with file:line.

#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"
#include "skelgraph/runtime/component.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/registry.hpp"
#include "skelgraph/runtime/topics.hpp"

namespace skelgraph::calib {

class CalibrationComponent final : public runtime::Component {
 public:
  CalibrationComponent(runtime::Context& ctx, const runtime::Params& params)
      : Component(ctx), path_(params.get<std::string>("file")), pub_(ctx, runtime::topics::kCalibration) {
    if (path_.empty()) throw std::invalid_argument("calibration: parameter 'file' is required (a YAML under bringup/calib/)");
    try {
      file_ = read_calib_file(path_);
    } catch (const CalibFileError& e) {
      throw std::invalid_argument(e.what());
    }
  }

  static runtime::ComponentInfo describe() {
    runtime::ComponentInfo info{"calibration",
                                "Publishes the sensor poses of a calibration file (bringup/calib/*.yaml) on "
                                "skelgraph/calibration",
                                {}};
    info.params.add_string("file", "", "calibration YAML (written by `skelgraph calib ...`)");
    return info;
  }

  void on_start() override {
    for (auto p : file_.sensors) {
      p.stamp_ns = ctx_.clock().now_ns();
      pub_.publish(skeleton::to_msg(p));
      ++published_;
    }
    ctx_.set_health(runtime::HealthState::Ok,
                    "published " + std::to_string(published_) + " sensor pose(s) from " + path_);
  }

  std::string summary() const override {
    return std::to_string(published_) + " pose(s) in frame '" + file_.frame_id + "' from " + path_;
  }
  nlohmann::json details() const override {
    nlohmann::json sensors = nlohmann::json::array();
    for (const auto& s : file_.sensors) sensors.push_back(s.sensor_id);
    return {{"file", path_}, {"frame_id", file_.frame_id}, {"sensors", sensors}, {"published", published_}};
  }

 private:
  std::string path_;
  CalibFile file_;
  runtime::Publisher<msg::SensorPose> pub_;
  std::size_t published_ = 0;
};

}  // namespace skelgraph::calib

SKELGRAPH_REGISTER_COMPONENT(calibration, skelgraph::calib::CalibrationComponent)
