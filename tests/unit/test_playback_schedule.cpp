#include <gtest/gtest.h>

#include "skelgraph/playback/schedule.hpp"

using namespace skelgraph;
using playback::PlaybackSchedule;

namespace {
constexpr std::int64_t kMs = 1'000'000;
std::vector<skeleton::Skeleton> frames(std::initializer_list<std::int64_t> stamps_ms) {
  std::vector<skeleton::Skeleton> out;
  std::uint64_t n = 0;
  for (auto t : stamps_ms) {
    skeleton::Skeleton s;
    s.stamp_ns = 5'000 * kMs + t * kMs;  // recordings start at arbitrary clock values
    s.frame_number = n++;
    out.push_back(s);
  }
  return out;
}
std::vector<std::uint64_t> numbers(const std::vector<skeleton::Skeleton>& v) {
  std::vector<std::uint64_t> out;
  for (const auto& s : v) out.push_back(s.frame_number);
  return out;
}
}  // namespace

TEST(PlaybackSchedule, RecordedRateAndRestamping) {
  PlaybackSchedule p(frames({0, 33, 66, 100}), {});
  const std::int64_t start = 1'000'000 * kMs;
  auto a = p.due(0, start);
  ASSERT_EQ(numbers(a), (std::vector<std::uint64_t>{0}));
  EXPECT_EQ(a[0].stamp_ns, start);
  EXPECT_TRUE(p.due(32 * kMs, start).empty());
  auto b = p.due(70 * kMs, start);
  ASSERT_EQ(numbers(b), (std::vector<std::uint64_t>{1, 2}));
  EXPECT_EQ(b[1].stamp_ns, start + 66 * kMs);
  EXPECT_FALSE(p.finished());
  EXPECT_EQ(numbers(p.due(1000 * kMs, start)), (std::vector<std::uint64_t>{3}));
  EXPECT_TRUE(p.finished());
  EXPECT_EQ(p.published(), 4u);
  EXPECT_TRUE(p.due(5000 * kMs, start).empty());
}

TEST(PlaybackSchedule, RateScalesTimeAndOrderIsByStamp) {
  PlaybackSchedule::Options o;
  o.rate = 2.0;
  o.restamp = false;
  auto in = frames({100, 0, 50});  // out of order on input
  PlaybackSchedule p(in, o);
  auto a = p.due(25 * kMs, 0);  // 50 ms of recording at 2x
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].frame_number, 1u);
  EXPECT_EQ(a[1].frame_number, 2u);
  EXPECT_EQ(a[1].stamp_ns, 5'050 * kMs);  // original stamps kept
}

TEST(PlaybackSchedule, LoopRepeatsAfterOnePeriod) {
  PlaybackSchedule::Options o;
  o.loop = true;
  PlaybackSchedule p(frames({0, 30, 60}), o);
  EXPECT_EQ(p.duration_ns(), 90 * kMs);
  EXPECT_EQ(p.due(89 * kMs, 0).size(), 3u);
  auto second = p.due(90 * kMs, 0);  // first frame of loop 2
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0].frame_number, 0u);
  EXPECT_EQ(second[0].stamp_ns, 90 * kMs);
  EXPECT_EQ(p.loops_completed(), 1u);
  EXPECT_FALSE(p.finished());
}

TEST(PlaybackSchedule, AsFastAsPossibleInBatches) {
  PlaybackSchedule::Options o;
  o.rate = 0.0;
  o.max_batch = 2;
  PlaybackSchedule p(frames({0, 10, 20, 30, 40}), o);
  EXPECT_EQ(p.due(0, 0).size(), 2u);
  EXPECT_EQ(p.due(0, 0).size(), 2u);
  EXPECT_EQ(p.due(0, 0).size(), 1u);
  EXPECT_TRUE(p.finished());
}

TEST(PlaybackSchedule, RejectsNegativeRate) {
  PlaybackSchedule::Options o;
  o.rate = -1.0;
  EXPECT_THROW(PlaybackSchedule(frames({0}), o), std::invalid_argument);
}
