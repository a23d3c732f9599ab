#pragma once
// A source's capture stamps onto the receiver's clock.
//
// Receive times carry the delivery: a publisher that falls behind (a busy
// host, a timer that fires late) sends a burst of frames that all arrive
// together, and pairing two sensors' skeletons by receive time then pairs
// poses taken up to the burst's length apart. The stamps keep the frames'
// spacing but run on the source's clock (another host's, a simulator's at
// another rate). The map fits receive = a + b * stamp by least squares over
// the last `window` samples, so a mapped stamp keeps the spacing of the
// stamps and lands on the receive clock (with the source's mean delay).
// A stamp that jumps (the source restarted) starts the fit again. Pure.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <utility>

namespace skelgraph::skeleton {

class StampMap {
 public:
  // window: samples kept; jump_ns: a sample this far from the fit starts it again.
  explicit StampMap(std::size_t window = 600, std::int64_t jump_ns = 1'000'000'000);

  void add(std::int64_t stamp_ns, std::int64_t receive_ns);
  // The stamp on the receive clock. With no sample yet: the stamp itself.
  std::int64_t to_receive(std::int64_t stamp_ns) const;
  // The fit's slope (receive ns per stamp ns; 1 when the clocks run at one rate).
  double rate() const { return slope_; }
  std::size_t size() const { return samples_.size(); }
  std::size_t restarts() const { return restarts_; }

 private:
  void fit();

  std::size_t window_;
  std::int64_t jump_ns_;
  std::deque<std::pair<std::int64_t, std::int64_t>> samples_;  // (stamp, receive)
  // receive = origin_receive_ + intercept_ + slope_ * (stamp - origin_stamp_)
  std::int64_t origin_stamp_ = 0, origin_receive_ = 0;
  double intercept_ = 0, slope_ = 1;
  std::size_t restarts_ = 0;
};

}  // namespace skelgraph::skeleton
