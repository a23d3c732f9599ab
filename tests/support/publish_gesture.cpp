// publish_gesture: a pointing GestureEvent with a ray and a floor target,
// twice a second for N seconds, on skelgraph/gesture/event (for the viewer's
// browser test: the page must draw the ray and the target and name them; for
// the LAN test: events that must reach every host's recorder).
//   publish_gesture [SECONDS] [LABEL] [READERS]   (default 10, "pointing", 1)
// Starts publishing once READERS readers have matched. On the "loopback"
// profile unless SKELGRAPH_PROFILE names another (the LAN test's hosts, inside
// their network namespaces).
// Every event: label LABEL, person 7, right arm, ray from (0, 1.4, 0)
// towards (1, -1, 0)/sqrt(2), target (1.4, 0, 0) named "floor".
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "skelgraph/runtime/context.hpp"
#include "skelgraph/runtime/pubsub.hpp"

int main(int argc, char** argv) {
  using namespace skelgraph;
  const double seconds = argc > 1 ? std::atof(argv[1]) : 10.0;
  const int readers = argc > 3 ? std::atoi(argv[3]) : 1;
  auto config = runtime::DdsConfig::from_env();
  if (std::getenv("SKELGRAPH_PROFILE") == nullptr) config.profile = "loopback";  // 127.0.0.1 and shared memory
  runtime::Context ctx("publish_gesture", config);
  runtime::Publisher<msg::GestureEvent> pub(ctx, runtime::topics::kGestureEvent);
  msg::GestureEvent e;
  e.label(argc > 2 ? argv[2] : "pointing");
  e.person_id(7);
  e.source("skelgraph/skeleton/fused");
  e.arm("right");
  e.score(2.0);
  e.confidence(1.0 - std::exp(-2.0));
  e.has_ray(true);
  e.has_target(true);
  e.ray_origin().y(1.4);
  e.ray_direction().x(std::sqrt(0.5));
  e.ray_direction().y(-std::sqrt(0.5));
  e.target().x(1.4);
  e.target_name("floor");
  // Events are not kept for late joiners (volatile): first a reader to hear them.
  if (!pub.wait_for_matched(static_cast<std::size_t>(readers), std::chrono::seconds(20))) {
    std::fprintf(stderr, "publish_gesture: not %d reader(s) of skelgraph/gesture/event within 20 s\n", readers);
    return 1;
  }
  const int count = static_cast<int>(seconds * 2);
  for (int i = 0; i < count; ++i) {
    e.start_stamp_ns(runtime::system_clock()->now_ns() - 500'000'000);
    e.end_stamp_ns(runtime::system_clock()->now_ns());
    if (!pub.publish(e)) {
      std::fprintf(stderr, "publish_gesture: event %d not published\n", i + 1);
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  std::fprintf(stderr, "publish_gesture: published %d events\n", count);
  return 0;
}
