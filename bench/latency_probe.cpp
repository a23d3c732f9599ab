// The robot's end of the latency benchmark (bench/latency_bench.sh).
//   latency_probe send SECONDS     publishes a full-size Skeleton on
//                                  skelgraph/bench/hop at 30 Hz, stamped when sent
//   latency_probe receive SECONDS  takes raw and fused skeletons, gesture
//                                  states and the hop messages, and prints as
//                                  JSON (p50, p99, max, in ms, n):
//     hop_ms           receipt minus send: one bare Fast DDS hop between two processes
//     raw_ms           raw skeletons, receipt minus capture stamp, the sensor's
//                      clock brought onto ours as fusion does (its quickest
//                      delivery in the run taken as instantaneous): how much
//                      later than its quickest each raw skeleton came
//     fused_newest_ms  fused skeletons, receipt minus the newest input's capture stamp
//     fused_oldest_ms  ... minus the oldest input's capture stamp
//     fused_stamp_ms   ... minus stamp_ns (the fusion time)
//     gesture_ms       gesture states decided on a fused skeleton, receipt minus that
//                      skeleton's newest capture stamp
// Both ends and the graph run on this machine: one clock.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"

using namespace skelgraph;

namespace {
// The hop travels as fused skeletons do (same type, same QoS).
const runtime::TopicDef<msg::Skeleton> kHop{"skelgraph/bench/hop", runtime::topics::kSkeletonFused.qos};

nlohmann::json stats(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const auto q = [&](double p) {
    return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
  };
  return {{"n", v.size()}, {"p50", q(0.5)}, {"p99", q(0.99)}, {"max", v.empty() ? 0.0 : v.back()}};
}
}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc == 3 ? argv[1] : "";
  if (mode != "send" && mode != "receive") {
    std::fprintf(stderr, "usage: latency_probe send|receive SECONDS\n");
    return 2;
  }
  const double seconds = std::atof(argv[2]);
  runtime::Context ctx("latency_" + mode, runtime::DdsConfig::from_env());
  if (mode == "send") {
    runtime::Publisher<msg::Skeleton> pub(ctx, kHop);
    msg::Skeleton s;
    s.sensor_id("hop");
    for (auto& c : s.covariance()) c.xx(1e-4f);  // (values do not change the size: fixed-size fields)
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    std::uint64_t n = 0;
    for (auto next = std::chrono::steady_clock::now(); next < end; next += std::chrono::microseconds(33333)) {
      std::this_thread::sleep_until(next);
      s.frame_number(++n);
      s.stamp_ns(ctx.clock().now_ns());
      pub.publish(s);
    }
    std::printf("%s\n", nlohmann::json{{"sent", n}}.dump().c_str());
    return 0;
  }
  std::mutex m;
  std::map<std::string, std::vector<double>> ms;
  std::map<std::pair<std::uint32_t, std::int64_t>, std::int64_t> newest_of;
  std::map<std::string, std::vector<std::int64_t>> raw_delay;  // per sensor: receipt - stamp (its own clock)  // fused (person, stamp) -> newest capture
  const auto add = [&](const char* what, std::int64_t receive, std::int64_t from) {
    ms[what].push_back(static_cast<double>(receive - from) * 1e-6);
  };
  runtime::Subscription<msg::Skeleton> hop(ctx, kHop, [&](const msg::Skeleton& s, const runtime::SampleMeta& meta) {
    std::lock_guard<std::mutex> lock(m);
    add("hop_ms", meta.receive_ns, s.stamp_ns());
  });
  runtime::Subscription<msg::Skeleton> raw(ctx, runtime::topics::kSkeletonRaw,
                                           [&](const msg::Skeleton& s, const runtime::SampleMeta& meta) {
                                             std::lock_guard<std::mutex> lock(m);
                                             raw_delay[s.sensor_id().to_string()].push_back(meta.receive_ns - s.stamp_ns());
                                           });
  runtime::Subscription<msg::Skeleton> fused(
      ctx, runtime::topics::kSkeletonFused, [&](const msg::Skeleton& s, const runtime::SampleMeta& meta) {
        std::lock_guard<std::mutex> lock(m);
        add("fused_newest_ms", meta.receive_ns, s.capture_newest_ns());
        add("fused_oldest_ms", meta.receive_ns, s.capture_oldest_ns());
        add("fused_stamp_ms", meta.receive_ns, s.stamp_ns());
        newest_of[{s.person_id(), s.stamp_ns()}] = s.capture_newest_ns();
        while (newest_of.size() > 4096) newest_of.erase(newest_of.begin());
      });
  runtime::Subscription<msg::GestureState> gesture(
      ctx, runtime::topics::kGestureState, [&](const msg::GestureState& g, const runtime::SampleMeta& meta) {
        std::lock_guard<std::mutex> lock(m);
        const auto it = newest_of.find({g.person_id(), g.stamp_ns()});
        if (it != newest_of.end()) add("gesture_ms", meta.receive_ns, it->second);
      });
  ctx.executor().start();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  std::lock_guard<std::mutex> lock(m);
  for (const auto& [sensor, d] : raw_delay) {
    const auto quickest = *std::min_element(d.begin(), d.end());
    for (const auto x : d) add("raw_ms", x, quickest);
  }
  nlohmann::json out = nlohmann::json::object();
  for (const char* k : {"hop_ms", "raw_ms", "fused_newest_ms", "fused_oldest_ms", "fused_stamp_ms", "gesture_ms"})
    out[k] = stats(ms[k]);
  std::printf("%s\n", out.dump().c_str());
  return 0;
}
