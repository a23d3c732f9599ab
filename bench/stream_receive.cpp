// Receiver for the transport benchmarks: takes skelgraph/depth (depth_bench)
// or skelgraph/skeleton/raw (secure_bench) for a given time and reports, per
// sensor, frames received, frames missing (gaps in frame numbers) and latency
// (receive time minus the publisher's stamp; both on this machine's clock),
// and this process's CPU time, as JSON.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <mutex>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"

using namespace skelgraph;

int main(int argc, char** argv) {
  const std::string topic = argc == 3 ? argv[2] : "depth";
  if ((argc != 2 && argc != 3) || (topic != "depth" && topic != "skeleton")) {
    std::fprintf(stderr, "usage: stream_receive SECONDS [depth|skeleton]\n");
    return 2;
  }
  const double seconds = std::atof(argv[1]);
  struct Stream {
    std::uint64_t received = 0, missing = 0, first = 0, last = 0;
    std::vector<double> latency_ms;
  };
  std::mutex m;
  std::map<std::string, Stream> streams;
  runtime::Context ctx("bench_receiver", runtime::DdsConfig::from_env());
  const auto take = [&](const std::string& sensor, std::uint64_t frame, std::int64_t stamp_ns,
                        const runtime::SampleMeta& meta) {
    std::lock_guard<std::mutex> lock(m);
    auto& s = streams[sensor];
    if (s.received == 0) s.first = frame;
    else if (frame > s.last + 1) s.missing += frame - s.last - 1;
    s.last = frame;
    ++s.received;
    s.latency_ms.push_back((meta.receive_ns - stamp_ns) * 1e-6);
  };
  std::unique_ptr<runtime::Subscription<msg::DepthFrame>> depth;
  std::unique_ptr<runtime::Subscription<msg::Skeleton>> skeleton;
  if (topic == "depth") {
    depth = std::make_unique<runtime::Subscription<msg::DepthFrame>>(
        ctx, runtime::topics::kDepth, [&](const msg::DepthFrame& f, const runtime::SampleMeta& meta) {
          take(f.sensor_id().to_string(), f.frame_number(), f.stamp_ns(), meta);
        });
  } else {
    skeleton = std::make_unique<runtime::Subscription<msg::Skeleton>>(
        ctx, runtime::topics::kSkeletonRaw, [&](const msg::Skeleton& f, const runtime::SampleMeta& meta) {
          take(f.sensor_id().to_string(), f.frame_number(), f.stamp_ns(), meta);
        });
  }
  ctx.executor().start();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  std::lock_guard<std::mutex> lock(m);
  nlohmann::json out = nlohmann::json::object();
  for (auto& [id, s] : streams) {
    auto& l = s.latency_ms;
    std::sort(l.begin(), l.end());
    const auto q = [&](double p) { return l.empty() ? 0.0 : l[std::min(l.size() - 1, static_cast<std::size_t>(p * l.size()))]; };
    out[id] = {{"received", s.received}, {"missing", s.missing}, {"first_frame", s.first}, {"last_frame", s.last},
               {"latency_ms_median", q(0.5)}, {"latency_ms_p99", q(0.99)}, {"latency_ms_max", l.empty() ? 0.0 : l.back()}};
  }
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double cpu = ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec + ru.ru_stime.tv_usec * 1e-6;
  std::printf("%s\n", nlohmann::json{{"streams", out}, {"cpu_s", cpu}, {"seconds", seconds}}.dump().c_str());
  return 0;
}
