// Which guard had a hand on a CAV that collided (GuardCounters::collided_*), on the tiny road,
// in-process: a handed-back CAV in a busy zone, under the busy zones' change bound, is made
// to run into a leader that stops dead; it must be counted as collided, handed back and
// bounded. The counting rule itself is checked on records alone.
// One libsumo simulation per process: one test that runs SUMO.
#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <algorithm>
#include <string>
#include <tuple>
#include <utility>

#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::sim::GuardCounters;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
// A hold long enough that a CAV stays bounded from its entry (which counts as a change) until
// it reaches its leader.
constexpr double BOUND_MPS2 = 1.2, HOLD_S = 60.0, FLOOR_SHARE = 0.3;

// A handed-back CAV on the mainline under the bound, well above the floor, with a tracked
// leader within 80 m: {cav, leader}, or empty.
std::pair<std::string, std::string> pickBoundedCavWithLeader(const SumoSession& session) {
  for (const VehicleRecord& v : session.vehicles()) {
    if (!v.is_cav || !v.guard.handed_back || !v.guard.busy_change_bounded || v.part != RoadPart::kMainline ||
        v.speed_mps < 1.5 * FLOOR_SHARE * v.max_speed_mps)
      continue;
    const auto ahead = libsumo::Vehicle::getLeader(v.id, 80.0);
    if (!ahead.first.empty() && session.find(ahead.first)) return {v.id, ahead.first};
  }
  return {};
}
}  // namespace

TEST(CollisionAttribution, CountsOnlyCavsAndEachGuardStateTheyWereIn) {
  GuardCounters g;
  VehicleRecord hdv;
  hdv.guard.handed_back = true;  // an HDV is never handed back; were it, it still would not count
  countCollidedUnderGuard(hdv, &g);
  EXPECT_EQ(g.collided_cavs, 0u);
  EXPECT_EQ(g.collided_handed_back, 0u);

  VehicleRecord advised;
  advised.is_cav = true;
  advised.lane_change_target = 2;
  advised.command = palcas::sim::HeldCommand::kAccelerate;
  countCollidedUnderGuard(advised, &g);
  VehicleRecord own_change;
  own_change.is_cav = true;
  own_change.guard.handed_back = true;
  own_change.guard.busy_change_bounded = true;
  countCollidedUnderGuard(own_change, &g);
  VehicleRecord free_driving;
  free_driving.is_cav = true;
  countCollidedUnderGuard(free_driving, &g);
  EXPECT_EQ(g.collided_cavs, 3u);
  EXPECT_EQ(g.collided_handed_back, 1u);
  EXPECT_EQ(g.collided_busy_change_bounded, 1u);
  EXPECT_EQ(g.collided_advised_change, 1u);
  EXPECT_EQ(g.collided_accelerate, 1u);
}

TEST(CollisionAttribution, ABoundedCavThatCollidesIsCountedAsBoundedAndHandedBack) {
  const SessionOptions options =
      palcas::sim::test::sessionOnTinyEveryZoneBusy("collision_attribution", 5, BOUND_MPS2, HOLD_S, FLOOR_SHARE);
  SumoSession session(options);
  for (int i = 0; i < 400; ++i) session.step();  // the road fills
  EXPECT_EQ(session.guardCounters().collided_cavs, 0u) << "a collision before the test made one";

  std::string id, leader;
  for (int i = 0; i < 300 && id.empty(); ++i) {
    session.step();
    std::tie(id, leader) = pickBoundedCavWithLeader(session);
  }
  ASSERT_FALSE(id.empty()) << "no bounded, handed-back CAV with a leader within 80 m";

  // The leader stops dead; the CAV ignores every safe-speed rule and keeps its speed.
  libsumo::Vehicle::setSpeedMode(leader, 0);
  libsumo::Vehicle::setSpeed(leader, 0.0);
  libsumo::Vehicle::setSpeedMode(id, 0);
  libsumo::Vehicle::setSpeed(id, session.find(id)->speed_mps);
  bool collided = false;
  for (int i = 0; i < 200 && !collided; ++i) {
    const palcas::sim::StepEvents& events = session.step();
    collided = std::find(events.collided.begin(), events.collided.end(), id) != events.collided.end();
    if (!collided) {
      ASSERT_NE(session.find(id), nullptr) << id << " left the road without colliding";
      ASSERT_TRUE(session.find(id)->guard.busy_change_bounded) << id << " released before it reached " << leader;
    }
  }
  ASSERT_TRUE(collided) << id << " never reached " << leader;
  const GuardCounters& g = session.guardCounters();
  EXPECT_GE(g.collided_cavs, 1u);
  EXPECT_GE(g.collided_busy_change_bounded, 1u);  // its leader may be a bounded CAV too
  EXPECT_GE(g.collided_handed_back, 1u);
  EXPECT_EQ(g.collided_advised_change, 0u) << "no advised change was under way";
  EXPECT_EQ(g.collided_accelerate, 0u) << "a handed-back CAV holds no advice";
}
