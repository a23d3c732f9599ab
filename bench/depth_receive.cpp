// Receiver for the depth transport benchmark: takes skelgraph/depth for a
// given time and reports, per sensor, frames received, frames missing (gaps
// in frame numbers) and latency (receive time minus the publisher's stamp;
// both on this host's clock) as JSON.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
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
  if (argc != 2) {
    std::fprintf(stderr, "usage: depth_receive SECONDS\n");
    return 2;
  }
  const double seconds = std::atof(argv[1]);
  struct Stream {
    std::uint64_t received = 0, missing = 0, first = 0, last = 0;
    std::vector<double> latency_ms;
  };
  std::mutex m;
  std::map<std::string, Stream> streams;
  runtime::Context ctx("bench_depth_receiver", runtime::DdsConfig::from_env());
  runtime::Subscription<msg::DepthFrame> sub(ctx, runtime::topics::kDepth,
                                              [&](const msg::DepthFrame& f, const runtime::SampleMeta& meta) {
                                                std::lock_guard<std::mutex> lock(m);
                                                auto& s = streams[f.sensor_id().to_string()];
                                                if (s.received == 0) s.first = f.frame_number();
                                                else if (f.frame_number() > s.last + 1) s.missing += f.frame_number() - s.last - 1;
                                                s.last = f.frame_number();
                                                ++s.received;
                                                s.latency_ms.push_back((meta.receive_ns - f.stamp_ns()) * 1e-6);
                                              });
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
  std::printf("%s\n", out.dump().c_str());
  return 0;
}
