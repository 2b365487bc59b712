// The SUMO session on the tiny road, in-process: an advised lane change happens within its
// 2 s under its acceleration bounds, and advisories the session cannot apply are refused. One libsumo simulation per
// process: one test. (Lane changes asked for while a CAV's back is still on a junction,
// which aborted SUMO 1.15, are covered by palcas_tests/training_smoke.test, the run that
// reproduced it.)
#include "palcas_sim/sumo_session.h"

#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <cmath>

#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
constexpr int LANE_LEFT = 0, ACCELERATE = 2, KEEP = 3;

SessionOptions tinyOptions() {
  SessionOptions o = palcas::sim::test::sessionOnTiny("session");
  o.guard.floor_speed_share = 0.0;  // the actuation itself (advice_guard_test: with the guard)
  o.guard.busy_speed_share = 0.0;
  o.guard.busy_leave_share = 0.0;
  o.guard.insertion_edge = false;  // its own test: insertion_guard_test
  return o;
}
// The lane-change model checks the others' gaps (cav_lane_change_mode 1536): pick a CAV
// with nobody in lane 2 from 80 m behind to 40 m ahead.
bool leftLaneFree(const SumoSession& session, const VehicleRecord& ego) {
  for (const VehicleRecord& o : session.vehicles())
    if (o.lane == 2 && o.x_m > ego.x_m - 80.0 && o.x_m < ego.x_m + 40.0) return false;
  return true;
}
}  // namespace

TEST(SumoSession, AdvisedLaneChangeHappensAndBadAdvisoriesAreRefused) {
  SessionOptions options = tinyOptions();
  options.lane_change_max_accel_mps2 = 1.0;  // bounds while an advised change runs
  options.lane_change_max_decel_mps2 = 3.0;
  SumoSession session(options);
  ASSERT_EQ(session.road().numMainLanes(), 3);

  // 1. An advised lane change happens within the 2 s budget.
  bool changed = false;
  std::string mover;
  for (int i = 0; i < 3000 && mover.empty(); ++i) {
    session.step();
    for (const VehicleRecord& v : session.vehicles())
      if (v.part == RoadPart::kMainline && v.lane == 1 && v.lane_pos_m > v.length_m + 1.0 &&
          v.edge.find("merge") == std::string::npos && v.speed_mps > 3.0 && v.x_m < 200.0 &&
          leftLaneFree(session, v))
        mover = v.id;
  }
  ASSERT_FALSE(mover.empty()) << "no moving CAV on lane 1";
  const double own_accel = libsumo::Vehicle::getAccel(mover), own_decel = libsumo::Vehicle::getDecel(mover);
  ASSERT_GT(own_accel, 1.0);
  ASSERT_GT(own_decel, 3.0);
  session.applyAdvisory(mover, LANE_LEFT, 0.0);
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getAccel(mover), 1.0);
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getDecel(mover), 3.0);
  for (int i = 0; i < 25 && session.find(mover) && !changed; ++i) {
    session.step();
    if (!session.find(mover)) break;
    changed = session.find(mover)->lane == 2;
    if (!changed) { EXPECT_LE(session.find(mover)->accel_mps2, 1.0 + 1e-9) << "step " << i; }
  }
  EXPECT_TRUE(changed) << mover << " did not reach lane 2 within 2.5 s";
  EXPECT_GE(session.laneChangesDone(), 1u);
  session.step();  // the change is seen done: the vehicle's own limits come back
  ASSERT_NE(session.find(mover), nullptr);
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getAccel(mover), own_accel);
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getDecel(mover), own_decel);

  // 2. Own car following: ACCELERATE brakes for its hold; once the command ends the CAV's
  // own model speeds it up again (a frozen speed would stay where the braking left it).
  std::string braker;
  for (const VehicleRecord& v : session.vehicles())
    if (v.part == RoadPart::kMainline && v.speed_mps > 15.0 && v.x_m < 150.0) braker = v.id;
  ASSERT_FALSE(braker.empty()) << "no fast CAV near the start";
  const double v0 = session.find(braker)->speed_mps;
  // -3 is clipped to the comfort band (max_advised_accel_mps2 1.47, as shipped).
  session.applyAdvisory(braker, ACCELERATE, -3.0);
  EXPECT_DOUBLE_EQ(session.find(braker)->command_value, -1.47);
  for (int i = 0; i < 10 && session.find(braker); ++i) session.step();
  ASSERT_NE(session.find(braker), nullptr);
  const double braked = session.find(braker)->speed_mps;
  EXPECT_LT(braked, v0 - 1.0) << braker;
  session.endCommand(braker);
  for (int i = 0; i < 20 && session.find(braker); ++i) session.step();
  if (session.find(braker)) { EXPECT_GT(session.find(braker)->speed_mps, braked + 1.0) << braker; }

  // 3. Own merge: CAVs from the on-ramps reach the mainline without any advisory.
  bool merged = false;
  for (int i = 0; i < 1500 && !merged; ++i) {
    session.step();
    for (const VehicleRecord& v : session.vehicles())
      merged = merged || (v.entry_cluster >= 0 && v.part == RoadPart::kMainline && v.lane >= 1 &&
                          v.id != mover && v.id != braker);
  }
  EXPECT_TRUE(merged) << "no ramp CAV merged by itself";

  // 4. Advisories the session cannot apply are refused, naming the problem. A lane that
  // does not exist is the validator's to refuse, against what the session knows of the CAV.
  EXPECT_THROW(session.applyAdvisory("no_such_vehicle", KEEP, 0.0), std::invalid_argument);
  EXPECT_FALSE(session.known("no_such_vehicle").exists);
  bool leftmost_seen = false;
  for (const VehicleRecord& v : session.vehicles())
    if (v.part == RoadPart::kMainline && v.lane == 3 && session.road().hasEdge(v.edge)) {
      palcas::metrics::AdvisoryRequest left;
      left.vehicle_id = v.id;
      left.action_code = LANE_LEFT;
      left.answers_step = session.stepCount();
      const auto verdict = palcas::metrics::validateAdvisory(left, session.stepCount(), session.known(v.id), {}, {});
      EXPECT_FALSE(verdict.accepted) << v.id;
      EXPECT_EQ(verdict.reason, palcas::metrics::RejectionReason::kNoSuchLane) << verdict.detail;
      leftmost_seen = true;
      break;
    }
  EXPECT_TRUE(leftmost_seen) << "no mainline vehicle in lane 3";
  EXPECT_THROW(session.applyAdvisory(session.vehicles().front().id, 9, 0.0), std::invalid_argument);
  // A NaN acceleration is refused and the vehicle keeps the command it held.
  const std::string first = session.vehicles().front().id;
  session.applyAdvisory(first, ACCELERATE, 1.0);
  EXPECT_THROW(session.applyAdvisory(first, ACCELERATE, std::nan("")), std::invalid_argument);
  EXPECT_DOUBLE_EQ(session.find(first)->command_value, 1.0);
}
