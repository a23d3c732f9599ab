#include "skelgraph/eval/recording.hpp"
#include "skelgraph/eval/report.hpp"
#include "skelgraph/skeleton/json_number.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/runtime/ordered_queue.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::eval {

namespace {


// Which evaluated stream a channel carries (raw, truth, recorded live fusion), if any.
std::optional<TimedSkeleton::Kind> skeleton_kind(const mcap::Channel& ch, const mcap::Schema* schema) {
  if (schema == nullptr || schema->name != msg::MessageTraits<msg::Skeleton>::name) return std::nullopt;
  if (ch.topic == runtime::topics::kSkeletonRaw.name) return TimedSkeleton::Kind::Raw;
  if (ch.topic == runtime::topics::kSkeletonTruth.name) return TimedSkeleton::Kind::Truth;
  if (ch.topic == runtime::topics::kSkeletonFused.name) return TimedSkeleton::Kind::Fused;
  return std::nullopt;
}

skeleton::Skeleton skeleton_of(const mcap::Message& m) {
  return skeleton::from_msg(
      msg::from_cdr<msg::Skeleton>(reinterpret_cast<const std::uint8_t*>(m.data.data()), m.data.size()));
}

}  // namespace

RecordingInputs read_recording(const std::string& file, bool shared_frame, const std::string& calibration) {
  RecordingInputs in;
  in.file = file;
  try {
    const mcap::Reader reader(file);
    std::int64_t latest = std::numeric_limits<std::int64_t>::min();
    reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
      if (schema == nullptr) return;
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(m.data.data());
      if (schema->name == msg::MessageTraits<msg::SensorPose>::name && ch.topic == runtime::topics::kCalibration.name) {
        const auto p = skeleton::from_msg(msg::from_cdr<msg::SensorPose>(bytes, m.data.size()));
        if (p.frame_id == "world") in.poses[p.sensor_id] = p.pose;
      } else if (ch.topic == runtime::topics::kSync.name && schema->name == msg::MessageTraits<msg::SyncCommand>::name) {
        if (msg::from_cdr<msg::SyncCommand>(bytes, m.data.size()).kind() == msg::SYNC_TICK) {
          in.ticks.push_back(static_cast<std::int64_t>(m.log_time));
        }
      }
      const auto kind = skeleton_kind(ch, schema);
      if (!kind) return;
      const auto t = static_cast<std::int64_t>(m.log_time);
      if (latest != std::numeric_limits<std::int64_t>::min()) in.lateness_ns = std::max(in.lateness_ns, latest - t);
      latest = std::max(latest, t);
      if (*kind == TimedSkeleton::Kind::Truth) {
        ++in.truth;
        return;
      }
      const auto id = skeleton_of(m).sensor_id;
      auto& ids = *kind == TimedSkeleton::Kind::Raw ? in.sensor_ids : in.recorded_ids;
      if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
      ++(*kind == TimedSkeleton::Kind::Raw ? in.raw : in.fused);
    });
  } catch (const mcap::McapError& e) {
    throw RecordingError(e.what());
  }
  std::sort(in.ticks.begin(), in.ticks.end());
  if (in.raw == 0) throw RecordingError(file + ": no raw skeletons on " + runtime::topics::kSkeletonRaw.name);
  if (!calibration.empty()) {
    try {
      for (const auto& p : calib::read_calib_file(calibration).sensors) in.poses[p.sensor_id] = p.pose;
    } catch (const calib::CalibFileError& e) {
      throw RecordingError(e.what());
    }
  }
  for (const auto& id : in.sensor_ids) {
    if (shared_frame) in.poses.try_emplace(id, Eigen::Isometry3d::Identity());
    if (!in.poses.count(id)) {
      throw RecordingError(file + ": no pose of sensor '" + id + "' on " + runtime::topics::kCalibration.name +
                           " (calibrate it, record the calibration topic, or --shared-frame if the data is already in "
                           "one frame)");
    }
  }
  return in;
}

void stream_recording(const RecordingInputs& in, Evaluator& ev, const MessageHook& each, const ProgressFn& progress) {
  runtime::OrderedQueue<TimedSkeleton> held;
  held.add_stream(0, in.lateness_ns);
  std::uint64_t seen = 0;
  const std::uint64_t total = in.raw + in.truth + in.fused;
  const auto add = [&](std::int64_t, TimedSkeleton&& e) { ev.add(std::move(e)); };
  try {
    const mcap::Reader reader(in.file);
    reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
      if (const auto kind = skeleton_kind(ch, schema)) {
        if (progress && total > 40'000 && seen % 5000 == 0) {  // (over ~10 minutes of two sensors)
          progress(in.file + ": " + std::to_string(seen) + " of " + std::to_string(total) +
                   " skeletons fused and scored (" + std::to_string(100 * seen / std::max<std::uint64_t>(1, total)) +
                   " %)");
        }
        ++seen;
        const auto t = static_cast<std::int64_t>(m.log_time);
        held.push(0, t, {*kind, t, skeleton_of(m)});
        held.drain(add);
      }
      if (each) each(ch, m);
    });
  } catch (const mcap::McapError& e) {
    throw RecordingError(e.what());
  }
  held.flush(add);
}

OfflineOptions offline_options(const std::vector<std::string>& methods, double delay_ms, double max_age_ms) {
  OfflineOptions eo;
  if (!methods.empty()) {
    eo.methods.clear();
    for (const auto& m : methods) {
      const auto method = fusion::method_from_name(m);
      if (!method) throw RecordingError("no fusion method '" + m + "'");
      eo.methods.push_back(*method);
    }
  }
  eo.fuser.delay_ns = static_cast<std::int64_t>(delay_ms * 1e6);
  eo.fuser.max_age_ns = static_cast<std::int64_t>(max_age_ms * 1e6);
  return eo;
}

OfflineOptions offline_options(const RecordingOptions& o, const RecordingInputs& in) {
  auto eo = offline_options(o.methods, o.delay_ms, o.max_age_ms);
  eo.tick_times = in.ticks;
  eo.fuser.predict_ns = static_cast<std::int64_t>(o.predict_ms * 1e6);
  eo.use_delay_ns = static_cast<std::int64_t>(o.use_delay_ms * 1e6);
  return eo;
}

ScoredRecording score_recording(const std::string& file, const RecordingOptions& o, bool trace,
                                const ProgressFn& progress) {
  ScoredRecording s{read_recording(file, o.shared_frame, o.calibration), {}, {}};
  auto eo = offline_options(o, s.in);
  eo.trace = trace;
  Evaluator ev(s.in.poses, s.in.sensor_ids, s.in.recorded_ids, eo);
  stream_recording(s.in, ev, {}, progress);
  s.result = ev.finish();
  nlohmann::json streams = nlohmann::json::array();
  for (const auto& st : s.result.streams) streams.push_back(stream_json(st));
  s.summary = {{"file", file},
               {"has_truth", s.result.has_truth},
               {"ticks", s.result.ticks},
               {"on_sync_ticks", !s.in.ticks.empty()},
               {"raw_skeletons", s.in.raw},
               {"truth_skeletons", s.in.truth},
               {"live_fused_skeletons", s.in.fused},
               {"predict_ms", o.predict_ms},
               {"use_delay_ms", o.use_delay_ms},
               {"streams", streams}};
  return s;
}

nlohmann::json fuse_recording(const std::string& file, const std::string& out, const RecordingOptions& o,
                              const ProgressFn& progress) {
  const auto in = read_recording(file, o.shared_frame, o.calibration);
  auto eo = offline_options(o, in);
  eo.singles = false;  // only the methods go into the file
  // One pass: every message is copied in file order, each after the fused
  // skeletons up to its log time; a message waits only until the fusion has
  // got that far (a few seconds), so neither side is held whole.
  std::deque<std::pair<std::int64_t, skeleton::Skeleton>> fused;  // in time order, as the ticks make them
  std::uint64_t fused_count = 0, copied = 0;
  Evaluator ev(in.poses, in.sensor_ids, {}, eo, [&](fusion::Method m, const skeleton::Skeleton& s) {
    auto f = s;
    f.sensor_id = eo.methods.size() == 1 ? "fused" : std::string("fused_") + fusion::method_name(m);
    fused.emplace_back(s.stamp_ns + eo.fuser.delay_ns, std::move(f));
    ++fused_count;
  });
  struct Copy {
    std::string topic, type;
    bool keyed;
    std::string data;
    std::uint64_t log_time, publish_time;
  };
  std::deque<Copy> copies;
  OfflineResult r;
  try {
    recording::BagWriter bag(out);
    const auto fused_until = [&](std::uint64_t t) {
      for (; !fused.empty() && static_cast<std::uint64_t>(std::max<std::int64_t>(0, fused.front().first)) <= t;
           fused.pop_front()) {
        const auto at = static_cast<std::uint64_t>(std::max<std::int64_t>(0, fused.front().first));
        bag.write(runtime::topics::kSkeletonFused.name, skeleton::to_msg(fused.front().second), at, at);
      }
    };
    const auto copy_until = [&](std::int64_t done) {
      for (; !copies.empty() && (done == std::numeric_limits<std::int64_t>::max() ||
                                 (done >= 0 && copies.front().log_time <= static_cast<std::uint64_t>(done)));
           copies.pop_front()) {
        const auto& c = copies.front();
        fused_until(c.log_time);
        bag.write_cdr(c.topic, c.type, c.keyed, c.data, c.log_time, c.publish_time);
        ++copied;
      }
    };
    stream_recording(
        in, ev,
        [&](const mcap::Channel& ch, const mcap::Message& m) {
          if (ch.topic == runtime::topics::kSkeletonFused.name) return;  // replaced
          const auto type = ch.metadata.count("dds_type") ? ch.metadata.at("dds_type") : std::string();
          const bool keyed = ch.metadata.count("keyed") && ch.metadata.at("keyed") == "true";
          copies.push_back({ch.topic, type, keyed, std::string(m.data.begin(), m.data.end()), m.log_time, m.publish_time});
          copy_until(ev.done_until());
        },
        progress);
    r = ev.finish();
    copy_until(std::numeric_limits<std::int64_t>::max());
    fused_until(UINT64_MAX);
    bag.close();
  } catch (const mcap::McapError& e) {
    throw RecordingError(e.what());
  }
  nlohmann::json per = nlohmann::json::object();
  for (std::size_t i = 0; i < r.streams.size(); ++i) {
    per[r.streams[i].name] = {{"ticks_with_output", r.streams[i].with_output},
                              {"flips_corrected", r.fuser_stats[i].flips_corrected},
                              {"gated", r.fuser_stats[i].gated},
                              {"occluded_views", r.fuser_stats[i].occluded_views},
                              {"ghost_views", r.fuser_stats[i].ghost_views}};
  }
  return {{"in", file},   {"out", out},       {"copied", copied},  {"fused", fused_count},
          {"on_sync_ticks", !in.ticks.empty()}, {"ticks", r.ticks}, {"methods", per}};
}

}  // namespace skelgraph::eval
