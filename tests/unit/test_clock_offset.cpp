#include <gtest/gtest.h>

#include <cmath>

#include "skelgraph/sim/rng.hpp"
#include "skelgraph/sync/clock_offset.hpp"

using skelgraph::sync::ClockExchange;
using skelgraph::sync::ClockOffsetEstimator;

namespace {
// A host whose clock reads master + offset + drift * t, with one-way delays out and back.
ClockExchange exchange(double t_s, double offset_ms, double drift_ppm, double out_ms, double back_ms, double answer_ms) {
  const auto ns = [](double ms) { return static_cast<std::int64_t>(std::llround(ms * 1e6)); };
  const std::int64_t t1 = 1'000'000'000'000 + ns(t_s * 1e3);
  auto host = [&](std::int64_t master) {
    return master + ns(offset_ms) + static_cast<std::int64_t>(std::llround(drift_ppm * 1e-6 * static_cast<double>(master - 1'000'000'000'000)));
  };
  const std::int64_t t2 = host(t1 + ns(out_ms));
  const std::int64_t t3 = host(t1 + ns(out_ms + answer_ms));
  const std::int64_t t4 = t1 + ns(out_ms + answer_ms + back_ms);
  return {t1, t2, t3, t4};
}
}  // namespace

TEST(ClockOffset, SymmetricDelaysGiveTheExactOffset) {
  const auto e = exchange(0, 12.0, 0, 0.4, 0.4, 0.1);
  EXPECT_EQ(e.offset(), 12'000'000);
  EXPECT_EQ(e.delay(), 800'000);
}

TEST(ClockOffset, NoisyNetworkAndDriftAreEstimated) {
  skelgraph::sim::Rng rng(5);
  ClockOffsetEstimator est;
  EXPECT_FALSE(est.estimate().has_value());
  for (int i = 0; i < 300; ++i) {
    const double t = i / 30.0;
    // Mostly 0.2-0.6 ms each way, sometimes a 20 ms spike in one direction only (the worst case for NTP).
    const double out = rng.uniform(0.2, 0.6) + (rng.chance(0.1) ? 20.0 : 0.0);
    const double back = rng.uniform(0.2, 0.6);
    est.add(exchange(t, -7.0, 50.0, out, back, rng.uniform(0.05, 2.0)));
  }
  const auto e = est.estimate();
  ASSERT_TRUE(e.has_value());
  // True offset at the last exchange: -7 ms + 50 ppm * ~10 s = -6.5 ms.
  EXPECT_NEAR(static_cast<double>(e->offset_ns), -6.5e6, 0.3e6);
  EXPECT_NEAR(e->drift_ppm, 50.0, 10.0);
  EXPECT_LT(e->rtt_ns, 2'000'000);
  EXPECT_LT(e->samples, 300u);  // the spikes were left out
}

TEST(ClockOffset, OutOfOrderReadingsAreRefused) {
  ClockOffsetEstimator est;
  EXPECT_FALSE(est.add({100, 50, 40, 200}));  // the host answered before it received
  EXPECT_FALSE(est.add({100, 50, 60, 90}));   // the answer came back before the question left
  EXPECT_EQ(est.size(), 0u);
}
