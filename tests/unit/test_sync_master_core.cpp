#include <gtest/gtest.h>

#include "skelgraph/sync/sync_master_core.hpp"

using namespace skelgraph::sync;
using Kind = SyncEvent::Kind;

namespace {
constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kWall = 1'800'000'000LL * 1'000'000'000LL;  // a wall-clock epoch for stamps
SyncMasterCore::Config cfg(std::int64_t period_ms = 33, std::int64_t duration_ms = 0) {
  SyncMasterCore::Config c;
  c.tick_period_ns = period_ms * kMs;
  c.session_duration_ns = duration_ms * kMs;
  return c;
}
}  // namespace

TEST(SyncMasterCore, StartThenTicksOnSchedule) {
  SyncMasterCore core(cfg());
  const auto start = core.start("walk", 1000 * kMs, kWall);
  ASSERT_EQ(start.size(), 1u);
  EXPECT_EQ(start[0].kind, Kind::Start);
  EXPECT_EQ(start[0].label, "walk");
  EXPECT_EQ(start[0].tick, 0u);
  EXPECT_EQ(start[0].session_id, static_cast<std::uint32_t>(kWall / 1'000'000'000LL));
  EXPECT_TRUE(core.running());
  EXPECT_TRUE(core.advance(1000 * kMs + 32 * kMs, kWall).empty());
  auto t1 = core.advance(1000 * kMs + 33 * kMs, kWall + 33 * kMs);
  ASSERT_EQ(t1.size(), 1u);
  EXPECT_EQ(t1[0].kind, Kind::Tick);
  EXPECT_EQ(t1[0].tick, 1u);
  EXPECT_EQ(t1[0].stamp_ns, kWall + 33 * kMs);
  EXPECT_TRUE(core.advance(1000 * kMs + 34 * kMs, kWall).empty());  // no tick twice
  auto t3 = core.advance(1000 * kMs + 100 * kMs, kWall);            // two due at once
  ASSERT_EQ(t3.size(), 2u);
  EXPECT_EQ(t3[0].tick, 2u);
  EXPECT_EQ(t3[1].tick, 3u);
  EXPECT_EQ(core.ticks_sent(), 3u);
}

TEST(SyncMasterCore, StopReportsLastTickAndSilencesTicks) {
  SyncMasterCore core(cfg());
  core.start("a", 0, kWall);
  core.advance(200 * kMs, kWall);  // 6 ticks
  const auto stop = core.stop(kWall + 1, "req-1");
  ASSERT_EQ(stop.size(), 1u);
  EXPECT_EQ(stop[0].kind, Kind::Stop);
  EXPECT_EQ(stop[0].tick, 6u);
  EXPECT_EQ(stop[0].request_id, "req-1");
  EXPECT_FALSE(core.running());
  EXPECT_TRUE(core.advance(10'000 * kMs, kWall).empty());
  EXPECT_TRUE(core.stop(kWall).empty());  // idle: nothing to stop
}

TEST(SyncMasterCore, StartWhileRunningStopsFirstAndNewSessionIdIsDistinct) {
  SyncMasterCore core(cfg());
  const auto a = core.start("a", 0, kWall);
  const auto b = core.start("b", 50 * kMs, kWall + 50 * kMs, "req");  // same second
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].kind, Kind::Stop);
  EXPECT_EQ(b[0].session_id, a[0].session_id);
  EXPECT_EQ(b[1].kind, Kind::Start);
  EXPECT_EQ(b[1].label, "b");
  EXPECT_EQ(b[1].request_id, "req");
  EXPECT_EQ(b[1].session_id, a[0].session_id + 1);
  // Ticks restart from 1, timed from the new start.
  const auto t = core.advance(50 * kMs + 33 * kMs, kWall);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].tick, 1u);
  EXPECT_EQ(core.sessions_started(), 2u);
}

TEST(SyncMasterCore, DurationEndsSessionWithExactTickCount) {
  SyncMasterCore core(cfg(10, 100));  // 10 ms ticks for 100 ms: ticks 1..10
  core.start("d", 0, kWall);
  const auto ev = core.advance(500 * kMs, kWall);
  ASSERT_EQ(ev.size(), 11u);
  EXPECT_EQ(ev[9].tick, 10u);
  EXPECT_EQ(ev[10].kind, Kind::Stop);
  EXPECT_EQ(ev[10].tick, 10u);
  EXPECT_FALSE(core.running());
}

TEST(SyncMasterCore, LongStallSkipsOldTicksAndCountsThem) {
  auto c = cfg(10);
  c.max_catch_up = 5;
  SyncMasterCore core(c);
  core.start("s", 0, kWall);
  const auto ev = core.advance(1000 * kMs, kWall);  // 100 due
  ASSERT_EQ(ev.size(), 5u);
  EXPECT_EQ(ev.front().tick, 96u);
  EXPECT_EQ(ev.back().tick, 100u);
  EXPECT_EQ(core.ticks_skipped(), 95u);
}

TEST(SyncMasterCore, RejectsBadConfig) {
  EXPECT_THROW(SyncMasterCore(cfg(0)), std::invalid_argument);
  EXPECT_THROW(SyncMasterCore(cfg(10, -1)), std::invalid_argument);
}
