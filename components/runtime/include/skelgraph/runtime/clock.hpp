#pragma once
// The one clock of a component, injected through its Context (and DdsConfig):
// wall-clock time for stamps, monotonic time for intervals and pacing. The
// system's by default; another host's (offset) or a hand-driven one in tests.
// Production code never reads a clock hook from the environment.

#include <atomic>
#include <cstdint>
#include <memory>

namespace skelgraph::runtime {

class Clock {
 public:
  virtual ~Clock() = default;
  // Wall-clock time in ns since the Unix epoch: message stamps.
  virtual std::int64_t now_ns() const = 0;
  // Monotonic time in ns, arbitrary origin: intervals and pacing.
  virtual std::int64_t monotonic_ns() const = 0;
};

// The machine's clocks (std::chrono::system_clock and steady_clock).
class SystemClock final : public Clock {
 public:
  std::int64_t now_ns() const override;
  std::int64_t monotonic_ns() const override;
};
std::shared_ptr<const Clock> system_clock();

// Another clock with its wall-clock time shifted by `offset_ns` (monotonic
// time unchanged): a host whose clock is off, as tests of clock-offset
// estimation play one on a single machine.
class OffsetClock final : public Clock {
 public:
  OffsetClock(std::shared_ptr<const Clock> base, std::int64_t offset_ns) : base_(std::move(base)), offset_ns_(offset_ns) {}
  std::int64_t now_ns() const override { return base_->now_ns() + offset_ns_; }
  std::int64_t monotonic_ns() const override { return base_->monotonic_ns(); }
  std::int64_t offset_ns() const { return offset_ns_; }

 private:
  std::shared_ptr<const Clock> base_;
  std::int64_t offset_ns_;
};

// Driven by hand (tests): both clocks read the same value until set or advanced.
class FakeClock final : public Clock {
 public:
  explicit FakeClock(std::int64_t start_ns = 0) : t_(start_ns) {}
  std::int64_t now_ns() const override { return t_.load(); }
  std::int64_t monotonic_ns() const override { return t_.load(); }
  void set(std::int64_t t_ns) { t_.store(t_ns); }
  void advance(std::int64_t dt_ns) { t_.fetch_add(dt_ns); }

 private:
  std::atomic<std::int64_t> t_;
};

}  // namespace skelgraph::runtime
