// Load generator for the recording benchmark: N skeleton streams and M depth
// streams (640x480 uint16) at 30 Hz for a given time, after waiting for a
// reader on each topic. Prints what it published as JSON.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/dds_config.hpp"
#include "skelgraph/runtime/pubsub.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/runtime/type_policy.hpp"

using namespace skelgraph;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: publish_streams SKELETON_STREAMS DEPTH_STREAMS SECONDS\n");
    return 2;
  }
  const int skeletons = std::atoi(argv[1]), depths = std::atoi(argv[2]);
  const double seconds = std::atof(argv[3]);
  runtime::Context ctx("bench_publisher", runtime::DdsConfig::from_env());
  runtime::Publisher<msg::Skeleton> skel(ctx, runtime::topics::kSkeletonRaw);
  runtime::Publisher<msg::DepthFrame> depth(ctx, runtime::topics::kDepth);
  ctx.executor().start();
  if ((skeletons > 0 && !skel.wait_for_matched(1, std::chrono::seconds(20))) ||
      (depths > 0 && !depth.wait_for_matched(1, std::chrono::seconds(20)))) {
    std::fprintf(stderr, "no reader matched\n");
    return 1;
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));  // let discovery settle on the reader's side too
  msg::DepthFrame frame;
  frame.width(640);
  frame.height(480);
  std::vector<std::uint16_t> mm(640 * 480);
  for (std::size_t i = 0; i < mm.size(); ++i) mm[i] = static_cast<std::uint16_t>(800 + (i * 7) % 3000);
  frame.depth_mm(mm);
  msg::Skeleton s;
  std::uint64_t n_skel = 0, n_depth = 0, failed = 0;
  const auto period = std::chrono::nanoseconds(1'000'000'000 / 30);
  const auto t0 = std::chrono::steady_clock::now();
  auto next = t0;
  for (std::uint64_t k = 0; std::chrono::steady_clock::now() - t0 < std::chrono::duration<double>(seconds); ++k) {
    std::this_thread::sleep_until(next);
    next += period;
    for (int i = 0; i < skeletons; ++i) {
      s.sensor_id("sensor" + std::to_string(i + 1));
      s.frame_number(k);
      s.stamp_ns(runtime::system_clock()->now_ns());
      if (skel.publish(s)) ++n_skel; else ++failed;
    }
    for (int i = 0; i < depths; ++i) {
      frame.sensor_id("depth" + std::to_string(i + 1));
      frame.frame_number(k);
      frame.stamp_ns(runtime::system_clock()->now_ns());
      if (depth.publish(frame)) ++n_depth; else ++failed;
    }
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Large best-effort samples live in this process's shared-memory segment
  // until the reader has taken them: stay a moment so the last frames are not
  // destroyed in flight (a real source keeps running).
  std::this_thread::sleep_for(std::chrono::seconds(1));
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  const double cpu = ru.ru_utime.tv_sec + ru.ru_utime.tv_usec * 1e-6 + ru.ru_stime.tv_sec + ru.ru_stime.tv_usec * 1e-6;
  std::printf("%s\n", nlohmann::json{{"skeleton_raw", n_skel}, {"depth", n_depth}, {"failed", failed},
                                     {"seconds", elapsed}, {"depth_frame_bytes", mm.size() * 2}, {"cpu_s", cpu}}
                          .dump()
                          .c_str());
  return 0;
}
