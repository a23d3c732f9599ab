#include "skelgraph/playback/playback.hpp"

#include <chrono>
#include <sstream>

#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::playback {

runtime::ComponentInfo Playback::describe() {
  runtime::ComponentInfo info{"playback", "Replays recorded skeleton data sets on skelgraph/skeleton/raw", {}};
  info.params.add_string("format", "generic", "file format", format_names())
      .add_string_list("files", {}, "files to play (merged in time order)")
      .add_double("rate", 1.0, "speed: 1 = as recorded, 2 = twice as fast, 0 = as fast as possible", 0.0, 1000.0)
      .add_bool("loop", false, "start again at the end")
      .add_bool("restamp", true, "stamp frames with the playback clock (as a live sensor would)")
      .add_string("on_error", "stop", "a bad line in a file: stop (refuse to start) or skip it", {"stop", "skip"})
      .add_string("sensor_id", "", "sensor id to publish under (default: the format's)")
      .add_double("gone_after_s", 1.0,
                  "a person missing from the data this long (wall clock) has left: their instance is disposed", 0.05, 3600.0);
  return info;
}

Playback::Playback(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx), files_(params.get<std::vector<std::string>>("files")), pub_(ctx, runtime::topics::kSkeletonRaw) {
  if (files_.empty()) throw std::invalid_argument("parameter 'files' lists no file to play");
  const auto format = *format_from_name(params.get<std::string>("format"));
  ReadOptions opt;
  opt.on_error = params.get<std::string>("on_error") == "skip" ? ReadOptions::OnError::Skip : ReadOptions::OnError::Stop;
  opt.sensor_id = params.get<std::string>("sensor_id");
  std::vector<skeleton::Skeleton> frames;
  for (const auto& f : files_) {
    auto rec = read_recording(format, f, opt);  // DataError names file:line
    report_.lines += rec.report.lines;
    report_.skipped += rec.report.skipped;
    report_.repeated_stamps += rec.report.repeated_stamps;
    frames.insert(frames.end(), std::make_move_iterator(rec.frames.begin()), std::make_move_iterator(rec.frames.end()));
  }
  PlaybackSchedule::Options so;
  so.rate = params.get<double>("rate");
  so.loop = params.get<bool>("loop");
  so.restamp = params.get<bool>("restamp");
  schedule_ = std::make_unique<PlaybackSchedule>(std::move(frames), so);
  gone_after_ns_ = static_cast<std::int64_t>(params.get<double>("gone_after_s") * 1e9);
  if (report_.skipped > 0) {
    ctx.set_health(runtime::HealthState::Degraded, std::to_string(report_.skipped) + " bad line(s) skipped");
  }
}

void Playback::on_start() {
  start_mono_ns_ = ctx_.clock().monotonic_ns();
  start_stamp_ns_ = ctx_.clock().now_ns();
  timer_ = ctx_.executor().every(std::chrono::milliseconds(2), [this] { tick(); }, true);
}

void Playback::tick() {
  const auto now = ctx_.clock().monotonic_ns();
  for (const auto& s : schedule_->due(now - start_mono_ns_, start_stamp_ns_)) pub_.publish(skeleton::to_msg(s));
  // A data set says nothing of people leaving; one missing for a while has.
  pub_.dispose_idle(schedule_->finished() ? now + 1 : now - gone_after_ns_);
  if (schedule_->finished()) {
    timer_.cancel();
    ctx_.set_health(runtime::HealthState::Ok, "finished");
  }
}

nlohmann::json Playback::details() const {
  return {{"files", files_},
          {"frames", schedule_->size()},
          {"published", schedule_->published()},
          {"loops_completed", schedule_->loops_completed()},
          {"finished", schedule_->finished()},
          {"lines", report_.lines},
          {"skipped_lines", report_.skipped},
          {"repeated_stamps", report_.repeated_stamps}};
}

std::string Playback::summary() const {
  std::ostringstream os;
  os << "published " << schedule_->published() << " of " << schedule_->size() << " frames from " << files_.size()
     << " file(s)";
  if (schedule_->loops_completed() > 0) os << ", " << schedule_->loops_completed() << " loop(s)";
  if (report_.skipped > 0) os << ", " << report_.skipped << " bad line(s) skipped";
  return os.str();
}

}  // namespace skelgraph::playback

SKELGRAPH_REGISTER_COMPONENT(playback, skelgraph::playback::Playback)
