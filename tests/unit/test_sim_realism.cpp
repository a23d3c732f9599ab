// The simulator against the thesis (Tables 5.1/5.2): the same comparison
// `skelgraph sim table` prints, held to its loose tolerances.
#include <gtest/gtest.h>

#include <cmath>

#include "skelgraph/sim/realism.hpp"

using namespace skelgraph;

TEST(SimRealism, DetectionAndErrorsNearTheThesisOutsideOcclusion) {
  sim::RealismOptions opt;  // seed 1, two repeats
  std::size_t simulations = 0;
  const auto cells = sim::compare_with_thesis(opt, [&](const std::string&, const std::string&) { ++simulations; });
  EXPECT_EQ(simulations, 2 * sim::kThesisScenarios.size());
  ASSERT_EQ(cells.size(), 2 * sim::kThesisScenarios.size() * sim::kGroupCount);
  EXPECT_EQ(cells.front().profile, "mssdk");
  EXPECT_EQ(cells[1].scenario, sim::kThesisScenarios[1]);  // scenarios within a group
  EXPECT_EQ(cells[sim::kThesisScenarios.size()].group, 1u);
  for (const auto& c : cells) {
    SCOPED_TRACE(c.profile + " " + c.scenario + " " + sim::group_names()[c.group]);
    const auto t = sim::thesis_figures(c.scenario, c.profile)[c.group];
    EXPECT_EQ(c.thesis.detection_pct, t.detection_pct);
    EXPECT_EQ(c.detection_close, sim::detection_close(c.sim.detection_pct, t.detection_pct));
    EXPECT_TRUE(c.detection_close) << c.sim.detection_pct << " vs " << t.detection_pct;
    // Known gap (README): behind the wall the thesis's trackers erred by
    // 30-85 cm on average; the model's physical effects give less.
    if (c.scenario == "occ") continue;
    EXPECT_TRUE(c.error_close) << c.sim.error_cm << " vs " << t.error_cm;
  }
}

TEST(SimRealism, TheThesisFindingsHold) {
  sim::RealismOptions opt;
  auto mean_error = [&](const std::string& scenario, const std::string& profile) {
    const auto f = sim::simulate_figures(scenario, profile, opt);
    double sum = 0;
    for (const auto& g : f) sum += g.error_cm;
    return sum / static_cast<double>(f.size());
  };
  auto detection = [&](const std::string& scenario, const std::string& profile, std::size_t group) {
    return sim::simulate_figures(scenario, profile, opt)[group].detection_pct;
  };
  constexpr std::size_t kShoulders = 3, kHands = 5;
  // Turning round is where the arms go wrong (flips): hands err several times more than walking.
  EXPECT_GT(mean_error("360", "nite"), 2.0 * mean_error("walk", "nite"));
  EXPECT_GT(mean_error("360", "mssdk"), 2.0 * mean_error("walk", "mssdk"));
  // MS-SDK drops confidence sooner: fewer tracked shoulders in 360, fewer hands in hide, fewer of anything in occ.
  EXPECT_LT(detection("360", "mssdk", kShoulders), detection("360", "nite", kShoulders) - 10);
  EXPECT_LT(detection("hide", "mssdk", kHands), detection("hide", "nite", kHands) - 20);
  EXPECT_LT(detection("occ", "mssdk", 0), detection("occ", "nite", 0) - 10);
  // ...and NITE's claims behind the wall are the worse ones.
  EXPECT_GT(mean_error("occ", "nite"), 1.5 * mean_error("occ", "mssdk"));
  EXPECT_GT(mean_error("occ", "nite"), 2.0 * mean_error("walk", "nite"));
}

TEST(SimRealism, ThesisTableIsTheOneInTheReference) {
  const auto walk = sim::thesis_figures("walk", "mssdk");
  EXPECT_EQ(walk[5].error_cm, 14.8);
  EXPECT_EQ(sim::thesis_figures("occ", "nite")[5].error_cm, 84.7);
  EXPECT_EQ(sim::thesis_figures("360", "mssdk")[3].detection_pct, 73);
  EXPECT_THROW(sim::thesis_figures("point", "nite"), std::invalid_argument);
  EXPECT_THROW(sim::thesis_figures("walk", "kinect"), std::invalid_argument);
}
