// Pause, resume, step and speed of a player of recordings (PlayGate).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "skelgraph/runtime/play_gate.hpp"

using skelgraph::runtime::PlayGate;
using K = PlayGate::Kind;

TEST(PlayGate, RunningPlayersDeliverUntilPaused) {
  PlayGate g(1.0);
  EXPECT_TRUE(g.may_deliver());
  EXPECT_FALSE(g.delivered(false));
  EXPECT_EQ(g.apply(K::Pause), "");
  EXPECT_FALSE(g.may_deliver());
  EXPECT_FALSE(g.take_repace());  // pausing needs no new pacing; resuming does
  EXPECT_EQ(g.apply(K::Resume), "");
  EXPECT_TRUE(g.may_deliver());
  EXPECT_TRUE(g.take_repace());
  EXPECT_FALSE(g.take_repace());  // once
}

TEST(PlayGate, StepsLetThatManyFramesThroughThenPauseAgain) {
  PlayGate g(1.0, /*paused=*/true);
  EXPECT_FALSE(g.may_deliver());
  EXPECT_EQ(g.apply(K::Step, 3), "");
  int delivered = 0;
  bool finished = false;
  while (g.may_deliver() && delivered < 10) {
    ++delivered;
    finished = g.delivered(g.paused());
  }
  EXPECT_EQ(delivered, 3);
  EXPECT_TRUE(finished);  // the third frame finished the request
  EXPECT_TRUE(g.paused());
  // Steps add up; a step pauses a running player; pause cancels what is left.
  g.apply(K::Step, 2);
  g.apply(K::Step, 2);
  EXPECT_EQ(g.steps_left(), 4u);
  g.apply(K::Pause);
  EXPECT_EQ(g.steps_left(), 0u);
  PlayGate running(1.0);
  running.apply(K::Step, 1);
  EXPECT_TRUE(running.paused());
  EXPECT_TRUE(running.may_deliver());
  EXPECT_TRUE(running.delivered(true));
  EXPECT_FALSE(running.may_deliver());
  // A frame let through while running, reported after a step came (a slow
  // player), is not one of the step's frames.
  PlayGate slow(1.0);
  ASSERT_TRUE(slow.may_deliver() && !slow.paused());  // granted running
  slow.apply(K::Pause);
  slow.apply(K::Step, 2);
  EXPECT_FALSE(slow.delivered(false));
  EXPECT_EQ(slow.steps_left(), 2u);
  EXPECT_FALSE(slow.delivered(true));
  EXPECT_TRUE(slow.delivered(true));
}

TEST(PlayGate, SpeedChangesRestartPacingAndBadRequestsAreRefused) {
  PlayGate g(1.0);
  EXPECT_EQ(g.apply(K::Speed, 0.0), "");  // as fast as possible
  EXPECT_EQ(g.speed(), 0.0);
  EXPECT_TRUE(g.take_repace());
  EXPECT_EQ(g.apply(K::Speed, 2.5), "");
  EXPECT_EQ(g.speed(), 2.5);
  for (double bad : {-1.0, 1001.0, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_NE(g.apply(K::Speed, bad), "") << bad;
    EXPECT_EQ(g.speed(), 2.5);
  }
  for (double bad : {0.0, -2.0, 1.5, 2e6, std::numeric_limits<double>::infinity()}) {
    EXPECT_NE(g.apply(K::Step, bad), "") << bad;
  }
  EXPECT_FALSE(g.paused());  // refused steps changed nothing
  EXPECT_THROW(PlayGate(-1.0), std::invalid_argument);
}

TEST(PlayGate, SeeksKeepPausedOrPlayingAndAreTakenOnce) {
  PlayGate gate(1.0, true);
  EXPECT_EQ(gate.take_seek(), std::nullopt);
  EXPECT_EQ(gate.apply(PlayGate::Kind::Seek, 12.5), "");
  EXPECT_EQ(gate.apply(PlayGate::Kind::Seek, 3.0), "");  // the latest wins
  EXPECT_TRUE(gate.paused());
  EXPECT_TRUE(gate.take_repace());
  EXPECT_EQ(gate.take_seek(), 3.0);
  EXPECT_EQ(gate.take_seek(), std::nullopt);
  EXPECT_EQ(gate.apply(PlayGate::Kind::Resume), "");
  EXPECT_EQ(gate.apply(PlayGate::Kind::Seek, 0.0), "");
  EXPECT_FALSE(gate.paused());
  EXPECT_NE(gate.apply(PlayGate::Kind::Seek, -1.0).find("0 or more"), std::string::npos);
  EXPECT_NE(gate.apply(PlayGate::Kind::Seek, std::nan("")), "");
  EXPECT_EQ(gate.take_seek(), 0.0);
}
