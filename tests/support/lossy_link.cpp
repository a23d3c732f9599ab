// lossy_link: an Ethernet link between two network namespaces made of two TAP
// devices and this process, which carries the frames across with a chosen
// loss, delay and up/down state: what `tc netem` would do, for kernels
// without sch_netem (tests/integration/lan.sh).
//
//   lossy_link NS_A IF_A NS_B IF_B [--seed N]
//
// creates TAP IF_A in /run/netns/NS_A and IF_B in /run/netns/NS_B (not yet
// up or addressed: the caller configures them), prints "ready", and relays
// until SIGINT/SIGTERM. Commands on stdin, one per line, apply to both
// directions: "loss P" (0..1), "delay MS", "down", "up", and "stats" (the
// counts so far as one JSON line: frames, dropped, delivered, and
// rtps_multicast: IPv4 frames to 239.255.0.0/16, DDS's multicast groups). Each
// is answered on stdout ("ok ..." or the JSON). The counts are printed at exit too.

#include <fcntl.h>
#include <linux/if.h>
#include <linux/if_tun.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <deque>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;
volatile sig_atomic_t g_stop = 0;

int open_tap_in(const std::string& ns, const std::string& name) {
  const int self = open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  const int target = open(("/run/netns/" + ns).c_str(), O_RDONLY | O_CLOEXEC);
  if (self < 0 || target < 0) throw std::runtime_error("no network namespace " + ns + " (ip netns add " + ns + ")");
  if (setns(target, CLONE_NEWNET) != 0) throw std::runtime_error("setns " + ns + ": " + std::strerror(errno));
  const int fd = open("/dev/net/tun", O_RDWR | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw std::runtime_error(std::string("/dev/net/tun: ") + std::strerror(errno));
  ifreq ifr{};
  ifr.ifr_flags = IFF_TAP | IFF_NO_PI;
  std::strncpy(ifr.ifr_name, name.c_str(), IFNAMSIZ - 1);
  if (ioctl(fd, TUNSETIFF, &ifr) != 0) throw std::runtime_error("TUNSETIFF " + name + ": " + std::strerror(errno));
  if (setns(self, CLONE_NEWNET) != 0) throw std::runtime_error(std::string("setns back: ") + std::strerror(errno));
  close(self);
  close(target);
  return fd;
}

struct Frame {
  Clock::time_point due;
  std::vector<unsigned char> bytes;
};

struct Direction {
  int from, to;
  std::deque<Frame> queue;  // constant delay: due times in order
  unsigned long long frames = 0, dropped = 0, delivered = 0, rtps_multicast = 0;
};

// An Ethernet frame carrying IPv4 to 239.255.x.x (RTPS multicast: discovery of the default profiles).
bool rtps_multicast(const unsigned char* f, std::size_t n) {
  return n >= 34 && f[12] == 0x08 && f[13] == 0x00 && f[30] == 239 && f[31] == 255;
}

std::string stats_json(const Direction (&d)[2]) {
  char out[512];
  std::snprintf(out, sizeof(out),
                "{\"a_to_b\": {\"frames\": %llu, \"dropped\": %llu, \"delivered\": %llu, \"rtps_multicast\": %llu}, "
                "\"b_to_a\": {\"frames\": %llu, \"dropped\": %llu, \"delivered\": %llu, \"rtps_multicast\": %llu}}",
                d[0].frames, d[0].dropped, d[0].delivered, d[0].rtps_multicast, d[1].frames, d[1].dropped,
                d[1].delivered, d[1].rtps_multicast);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: %s NS_A IF_A NS_B IF_B [--seed N]\n", argv[0]);
    return 2;
  }
  unsigned seed = 1;
  for (int i = 5; i + 1 < argc; i += 2) {
    if (std::string(argv[i]) == "--seed") seed = static_cast<unsigned>(std::stoul(argv[i + 1]));
  }
  signal(SIGINT, [](int) { g_stop = 1; });
  signal(SIGTERM, [](int) { g_stop = 1; });
  Direction d[2];
  try {
    const int a = open_tap_in(argv[1], argv[2]);
    const int b = open_tap_in(argv[3], argv[4]);
    d[0].from = a, d[0].to = b;
    d[1].from = b, d[1].to = a;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lossy_link: %s\n", e.what());
    return 1;
  }
  std::printf("ready\n");
  std::fflush(stdout);
  double loss = 0.0;
  auto delay = std::chrono::microseconds(0);
  bool up = true;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::string pending;
  std::vector<unsigned char> buf(65536);
  bool stdin_open = true;
  while (!g_stop) {
    // Wait for a frame, a command, or the next delayed frame's time.
    int timeout_ms = 100;
    for (const auto& dir : d) {
      if (!dir.queue.empty()) {
        const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(dir.queue.front().due - Clock::now()).count();
        timeout_ms = std::max(0, std::min<int>(timeout_ms, static_cast<int>(ms) + 1));
      }
    }
    pollfd fds[3] = {{d[0].from, POLLIN, 0}, {d[1].from, POLLIN, 0}, {stdin_open ? 0 : -1, POLLIN, 0}};
    if (poll(fds, 3, timeout_ms) < 0 && errno != EINTR) break;
    for (int k = 0; k < 2; ++k) {
      if (!(fds[k].revents & POLLIN)) continue;
      while (true) {
        const ssize_t n = read(d[k].from, buf.data(), buf.size());
        if (n <= 0) break;
        ++d[k].frames;
        if (rtps_multicast(buf.data(), static_cast<std::size_t>(n))) ++d[k].rtps_multicast;
        if (!up || uniform(rng) < loss) {
          ++d[k].dropped;
          continue;
        }
        d[k].queue.push_back({Clock::now() + delay, std::vector<unsigned char>(buf.begin(), buf.begin() + n)});
      }
    }
    if (fds[2].revents & (POLLIN | POLLHUP)) {
      char c[256];
      const ssize_t n = read(0, c, sizeof(c));
      if (n <= 0) {
        stdin_open = false;
      } else {
        pending.append(c, static_cast<std::size_t>(n));
      }
      std::size_t nl;
      while ((nl = pending.find('\n')) != std::string::npos) {
        std::istringstream line(pending.substr(0, nl));
        pending.erase(0, nl + 1);
        std::string cmd;
        double v = 0.0;
        line >> cmd >> v;
        if (cmd == "loss" && v >= 0.0 && v <= 1.0) {
          loss = v;
        } else if (cmd == "delay" && v >= 0.0) {
          delay = std::chrono::microseconds(static_cast<long long>(v * 1000.0));
        } else if (cmd == "down" || cmd == "up") {
          up = cmd == "up";
        } else if (cmd == "stats") {
          std::printf("%s\n", stats_json(d).c_str());
          std::fflush(stdout);
          continue;
        } else if (!cmd.empty()) {
          std::printf("error: unknown command '%s' (loss P | delay MS | down | up | stats)\n", cmd.c_str());
          std::fflush(stdout);
          continue;
        }
        if (!cmd.empty()) {
          std::printf("ok %s loss=%.3f delay_ms=%.1f %s\n", cmd.c_str(), loss, delay.count() / 1000.0, up ? "up" : "down");
          std::fflush(stdout);
        }
      }
    }
    const auto now = Clock::now();
    for (auto& dir : d) {
      while (!dir.queue.empty() && dir.queue.front().due <= now) {
        const auto& f = dir.queue.front().bytes;
        if (write(dir.to, f.data(), f.size()) == static_cast<ssize_t>(f.size())) ++dir.delivered;
        dir.queue.pop_front();
      }
    }
  }
  std::printf("%s\n", stats_json(d).c_str());
  return 0;
}
