#include <gtest/gtest.h>

#include "skelgraph/runtime/rate_stats.hpp"

using skelgraph::runtime::RateStats;

TEST(RateStats, RegularArrivals) {
  RateStats s;
  for (int i = 0; i <= 30; ++i) s.add(1'000'000'000LL + i * 33'000'000LL);
  const auto r = s.summary();
  EXPECT_EQ(r.samples, 31u);
  EXPECT_NEAR(r.rate_hz, 1.0 / 0.033, 1e-6);
  EXPECT_NEAR(r.min_period_s, 0.033, 1e-12);
  EXPECT_NEAR(r.max_period_s, 0.033, 1e-12);
  EXPECT_NEAR(r.std_period_s, 0.0, 1e-9);
}

TEST(RateStats, IrregularArrivalsGiveMinMaxStd) {
  RateStats s;
  const long long t[] = {0, 10'000'000, 40'000'000, 50'000'000, 80'000'000};  // 10, 30, 10, 30 ms
  for (auto x : t) s.add(x);
  const auto r = s.summary();
  EXPECT_NEAR(r.mean_period_s, 0.020, 1e-12);
  EXPECT_NEAR(r.min_period_s, 0.010, 1e-12);
  EXPECT_NEAR(r.max_period_s, 0.030, 1e-12);
  EXPECT_NEAR(r.std_period_s, 0.010, 1e-9);
  EXPECT_NEAR(r.rate_hz, 50.0, 1e-9);
}

TEST(RateStats, WindowForgetsOldArrivals) {
  RateStats s(1'000'000'000LL);  // 1 s
  for (int i = 0; i < 100; ++i) s.add(i * 100'000'000LL);  // 10 Hz for 10 s
  EXPECT_EQ(s.summary().samples, 11u);  // arrivals within [8.9 s, 9.9 s]
  EXPECT_EQ(s.total(), 100u);
  s.expire(20'000'000'000LL);
  EXPECT_EQ(s.summary().samples, 0u);
  EXPECT_EQ(s.summary().rate_hz, 0.0);
}
