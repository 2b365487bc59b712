// The SUMO session on the tiny road, in-process: an advised lane change happens within its
// 2 s, and advisories the session cannot apply are refused. One libsumo simulation per
// process: one test. (Lane changes asked for while a CAV's back is still on a junction,
// which aborted SUMO 1.15, are covered by palcas_tests/training_smoke.test, the run that
// reproduced it.)
#include "palcas_sim/sumo_session.h"

#include <gtest/gtest.h>


#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

using palcas::sim::RoadPart;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
constexpr int LANE_LEFT = 0, KEEP = 3;

SessionOptions tinyOptions() {
  palcas::sim::ScenarioConfig c;
  c.scenario_dir = palcas::sim::test::scenarioDir("tiny");
  c.cluster_length_m = 300.0;
  c.route_shares = palcas::sim::defaultRouteShares(2);  // the tiny road has two clusters
  c.penetration_rate = 1.0;  // every vehicle a CAV: plenty of candidates
  c.duration_s = 400.0;
  c.seed = 3;
  const auto files = palcas::sim::writeScenario(c, palcas::sim::test::freshDir("session"));
  SessionOptions o;
  o.sumo_args = {"-c", files.sumocfg_file, "--no-warnings", "true", "--no-step-log", "true",
                 "--time-to-teleport.remove", "true"};
  o.cluster_length_m = 300.0;
  o.advisory_control = true;
  return o;
}
}  // namespace

TEST(SumoSession, AdvisedLaneChangeHappensAndBadAdvisoriesAreRefused) {
  SumoSession session(tinyOptions());
  ASSERT_EQ(session.road().numMainLanes(), 3);

  // 1. An advised lane change happens within the 2 s budget.
  bool changed = false;
  std::string mover;
  for (int i = 0; i < 3000 && mover.empty(); ++i) {
    session.step();
    for (const VehicleRecord& v : session.vehicles())
    if (v.part == RoadPart::kMainline && v.lane == 1 && v.lane_pos_m > v.length_m + 1.0 &&
        v.edge.find("merge") == std::string::npos && v.speed_mps > 3.0 && v.x_m < 200.0)
        mover = v.id;
  }
  ASSERT_FALSE(mover.empty()) << "no moving CAV on lane 1";
  session.applyAdvisory(mover, LANE_LEFT, 0.0);
  for (int i = 0; i < 25 && session.find(mover); ++i) {
    session.step();
    changed = changed || (session.find(mover) && session.find(mover)->lane == 2);
  }
  EXPECT_TRUE(changed) << mover << " did not reach lane 2 within 2.5 s";

  // 2. Advisories the session cannot apply are refused, naming the problem.
  EXPECT_THROW(session.applyAdvisory("no_such_vehicle", KEEP, 0.0), std::invalid_argument);
  for (const VehicleRecord& v : session.vehicles())
    if (v.part == RoadPart::kMainline && v.lane == 3 && session.road().hasEdge(v.edge)) {
      EXPECT_THROW(session.applyAdvisory(v.id, LANE_LEFT, 0.0), std::invalid_argument) << v.id;
      break;
    }
  EXPECT_THROW(session.applyAdvisory(session.vehicles().front().id, 9, 0.0), std::invalid_argument);
}
