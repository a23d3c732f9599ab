// host_recording: one host's recording of a session, of about SIZE_MB, for the
// merge benchmark (bench/merge_bench.sh): 30 Hz depth frames (640x480, noisy:
// they do not compress) and skeletons of the host's sensor, the fused
// skeletons every host records (duplicates for the merge), and, on the
// master, the sync ticks; its clock `offset_ms` ahead, as a ClockOffset
// estimate says.
//   host_recording OUT.mcap HOST SIZE_MB [--master] [OFFSET_MS]
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "skelgraph/recording/bag.hpp"

int main(int argc, char** argv) {
  using namespace skelgraph;
  if (argc < 4) {
    std::fprintf(stderr, "usage: host_recording OUT.mcap HOST SIZE_MB [--master] [OFFSET_MS]\n");
    return 2;
  }
  const std::string out = argv[1], host = argv[2];
  const double size_mb = std::atof(argv[3]);
  const bool master = argc > 4 && std::string(argv[4]) == "--master";
  const double offset_ms = argc > 5 ? std::atof(argv[5]) : argc > 4 && !master ? std::atof(argv[4]) : 0.0;
  mcap::WriterOptions wo;
  wo.compression = mcap::Compression::None;
  recording::BagWriter bag(out, wo);
  bag.write_metadata("session", {{"host", host}});
  const std::uint64_t t0 = 1'800'000'000'000'000'000ULL;
  const auto offset = static_cast<std::int64_t>(offset_ms * 1e6);
  if (!master) {
    msg::ClockOffset c;
    c.host(host);
    c.offset_ns(offset);
    c.stamp_ns(static_cast<std::int64_t>(t0));
    bag.write("skelgraph/sync/clock", c, t0, t0);
  }
  std::mt19937 rng(1);
  std::uniform_int_distribution<int> depth(500, 4500);
  msg::DepthFrame d;
  d.sensor_id(host + "_depth");
  d.width(640);
  d.height(480);
  d.depth_mm().resize(640 * 480);
  std::uint64_t bytes = 0, frames = 0;
  for (std::uint64_t k = 0; bytes < size_mb * 1e6; ++k) {
    const std::uint64_t t = t0 + k * 33'333'333ULL;  // master clock
    const std::uint64_t local = t + static_cast<std::uint64_t>(offset);
    if (master) {
      msg::SyncCommand tick;
      tick.kind(msg::SYNC_TICK);
      tick.session_id(1);
      tick.tick(k);
      tick.master_stamp_ns(static_cast<std::int64_t>(t));
      bag.write("skelgraph/sync", tick, local, local);
    }
    for (auto& v : d.depth_mm()) v = static_cast<std::uint16_t>(depth(rng));
    d.frame_number(k);
    d.stamp_ns(static_cast<std::int64_t>(local));
    bag.write("skelgraph/depth", d, local + 5'000'000, local);
    msg::Skeleton s;
    s.sensor_id(host + "_sensor");
    s.person_id(1);
    s.frame_number(k);
    s.stamp_ns(static_cast<std::int64_t>(local));
    bag.write("skelgraph/skeleton/raw", s, local + 8'000'000, local);
    msg::Skeleton f;  // the same fused sample on every host
    f.sensor_id("fused");
    f.person_id(1);
    f.frame_number(k);
    f.stamp_ns(static_cast<std::int64_t>(t));
    bag.write("skelgraph/skeleton/fused", f, local + 12'000'000, t);
    bytes += 640 * 480 * 2 + 2000;
    ++frames;
  }
  bag.close();
  std::printf("%s: host %s, %llu frames, about %.0f MB\n", out.c_str(), host.c_str(),
              static_cast<unsigned long long>(frames), bytes / 1e6);
  return 0;
}
