#include <gtest/gtest.h>

#include "skelgraph/monitor/sync_watch.hpp"

using namespace skelgraph::monitor;

TEST(SyncWatch, CountsTicksGapsAndRatePerSession) {
  SyncWatch w;
  w.on_command(SyncWatch::Kind::Start, 7, "walk", 0, 0, 0);
  for (std::uint64_t k = 1; k <= 10; ++k) {
    if (k == 4 || k == 5) continue;  // lost
    // The master stamps every 33 ms; arrivals come late and in a burst at the start.
    const auto stamp = static_cast<std::int64_t>(k) * 33'000'000;
    w.on_command(SyncWatch::Kind::Tick, 7, "walk", k, stamp, k <= 3 ? 100'000'000 : stamp + 5'000'000);
  }
  w.on_command(SyncWatch::Kind::Stop, 7, "walk", 10, 400'000'000, 400'000'000);
  w.on_command(SyncWatch::Kind::Start, 8, "box", 0, 500'000'000, 500'000'000);
  const auto s = w.sessions();
  ASSERT_EQ(s.size(), 2u);
  EXPECT_TRUE(s[0].saw_start);
  EXPECT_TRUE(s[0].saw_stop);
  EXPECT_EQ(s[0].ticks, 8u);
  EXPECT_EQ(s[0].first_tick, 1u);
  EXPECT_EQ(s[0].last_tick, 10u);
  EXPECT_EQ(s[0].missing_ticks, 2u);
  EXPECT_EQ(s[0].stop_tick, 10u);
  EXPECT_NEAR(s[0].master_rate_hz, 1.0 / 0.033, 1e-6);  // from the master's stamps, gaps or not
  EXPECT_EQ(s[0].arrival.min_period_s, 0.0);            // the burst shows in the arrival statistics
  EXPECT_EQ(s[0].arrival.samples, 8u);
  EXPECT_EQ(s[1].label, "box");
  EXPECT_FALSE(s[1].saw_stop);
  EXPECT_EQ(s[1].ticks, 0u);
}
