// publish_skeleton: publishes Skeletons with fixed, known values on
// skelgraph/skeleton/raw through the project's runtime (so with our type
// policy), for tests that inspect them from another process.
//
//   publish_skeleton [--duration S]        (default 10 s, ~30 Hz)
//
// SIGINT/SIGTERM end it early with exit 0, so a test can keep it running for
// as long as it needs and still tell a clean stop from a crash.
//
// Every sample: sensor_id "probe_sensor", person_id 7, frame_id "world",
// joints[i].position = (i + 0.25, -i, 2 * i), orientation identity,
// confidence 1, sensor_mask 1 << i; frame_number counts from 0.
//
// SKELGRAPH_TEST_ANNOUNCE_TYPE_OBJECT=1 also announces the full TypeObject —
// the configuration rejected in docs/type-information.md — so a test can show
// that it still crashes Fast DDS peers that have not registered the type.

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/pubsub.hpp"

namespace {

using namespace skelgraph;

std::atomic<bool> stop_requested{false};
void request_stop(int) { stop_requested.store(true); }

msg::Skeleton make_skeleton() {
  msg::Skeleton s;
  s.sensor_id("probe_sensor");
  s.person_id(7);
  s.frame_id("world");
  for (std::size_t i = 0; i < s.joints().size(); ++i) {
    auto& j = s.joints()[i];
    const double d = static_cast<double>(i);
    j.position().x(d + 0.25);
    j.position().y(-d);
    j.position().z(2.0 * d);
    j.orientation().w(1.0);
    j.confidence(1.0F);
    j.sensor_mask(1U << i);
  }
  return s;
}

bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && std::strcmp(v, "1") == 0;
}

int run(double duration_s) {
  auto config = runtime::DdsConfig::from_env();
  config.profile = "loopback";
  runtime::Context ctx("publish_skeleton", config);
  if (env_flag("SKELGRAPH_TEST_ANNOUNCE_TYPE_OBJECT")) {
    // The writer fills its discovery data from the type support when it is
    // created, so the topic (policy applied) comes first, then the override,
    // then the writer; Publisher reuses the topic as it is.
    ctx.topic(runtime::topics::kSkeletonRaw.name, runtime::make_type_support<msg::Skeleton>());
    ctx.participant().find_type(msg::MessageTraits<msg::Skeleton>::name)->auto_fill_type_object(true);
    std::fprintf(stderr, "publish_skeleton: announcing the full TypeObject (rejected configuration)\n");
  }
  runtime::Publisher<msg::Skeleton> pub(ctx, runtime::topics::kSkeletonRaw);
  auto sample = make_skeleton();
  const auto period = std::chrono::microseconds(33333);
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(duration_s));
  auto next = start;
  std::uint64_t n = 0;
  while (!stop_requested.load() && std::chrono::steady_clock::now() < end) {
    sample.frame_number(n);
    sample.stamp_ns(runtime::system_clock()->now_ns());
    pub.publish(sample);
    ++n;
    next += period;
    std::this_thread::sleep_until(next);
  }
  std::fprintf(stderr, "publish_skeleton: published %llu samples\n", static_cast<unsigned long long>(n));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  double duration_s = 10.0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--duration") == 0 && i + 1 < argc) {
      duration_s = std::atof(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: publish_skeleton [--duration S]\n");
      return 2;
    }
  }
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  try {
    return run(duration_s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "publish_skeleton: %s\n", e.what());
    return 1;
  }
}
