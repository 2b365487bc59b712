// The guard's bound on a busy zone's own lane changes (GuardOptions::
// busy_change_max_accel_mps2) on the tiny road, in-process. A CAV handed back in a busy
// zone changes lanes by itself; around such a change (from when it moves sideways until
// guard_busy_change_hold_s after it is in its new lane) it accelerates at most at the bound,
// then its own acceleration comes back. Below the guard's floor it is never bounded.
// One libsumo simulation per process: one test.
#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
constexpr double BOUND_MPS2 = 1.2, HOLD_S = 3.0, FLOOR_SHARE = 0.3;

// A handed-back CAV in zone 0 that drives through (no off-ramp to turn into), with a lane to
// its left (the tiny road has three), well above the floor and not moving sideways: one whose
// change the test can start.
std::string pickCav(const SumoSession& session) {
  for (const VehicleRecord& v : session.vehicles())
    if (v.is_cav && v.guard.handed_back && v.exit_cluster < 0 && !v.guard.busy_change_bounded && v.part == RoadPart::kMainline &&
        v.lane <= 2 && !v.merge_mode && v.x_m > 20.0 && v.x_m < 200.0 &&
        v.speed_mps > 2.0 * FLOOR_SHARE * v.max_speed_mps && std::abs(v.lateral_speed_mps) < 0.05)
      return v.id;
  return {};
}
}  // namespace

TEST(BusyChangeBound, AnOwnChangeInABusyZoneAcceleratesGentlyThenItsOwnAccelComesBack) {
  const SessionOptions options =
      palcas::sim::test::sessionOnTinyEveryZoneBusy("busy_change_bound", 5, BOUND_MPS2, HOLD_S, FLOOR_SHARE);
  SumoSession session(options);
  for (int i = 0; i < 400; ++i) session.step();  // the road fills

  std::string id;
  for (int i = 0; i < 300 && id.empty(); ++i) {
    session.step();
    id = pickCav(session);
  }
  ASSERT_FALSE(id.empty()) << "no handed-back CAV in lanes 1-2 of zone 0 to try";
  const double own_accel = libsumo::Vehicle::getAccel(id);
  ASSERT_GT(own_accel, BOUND_MPS2);
  const auto bounds_before = session.guardCounters().busy_change_bounds;

  // Its own change, as SUMO's lane-change model would start it (the test asks SUMO for it).
  const int from_lane = session.find(id)->lane;
  libsumo::Vehicle::changeLane(id, session.find(id)->sumo_lane_index + 1, 5.0);
  double switched_at_s = -1.0;
  bool bounded_while_moving = false;
  for (int i = 0; i < 100 && switched_at_s < 0.0; ++i) {
    session.step();
    const VehicleRecord* v = session.find(id);
    ASSERT_NE(v, nullptr) << id << " left the road mid-change";
    if (v->lane != from_lane) switched_at_s = session.timeS();
    else if (std::abs(v->lateral_speed_mps) > 0.3)
      bounded_while_moving = bounded_while_moving || libsumo::Vehicle::getAccel(id) == BOUND_MPS2;
  }
  ASSERT_GE(switched_at_s, 0.0) << id << " never reached its new lane";
  EXPECT_TRUE(bounded_while_moving) << id << ": not bounded while it moved sideways";
  EXPECT_GT(session.guardCounters().busy_change_bounds, bounds_before);

  // Bounded through the hold after the switch (while it is handed back and fast enough), its
  // own accel after.
  int held_steps = 0;
  while (session.timeS() < switched_at_s + HOLD_S - 0.5) {
    session.step();
    const VehicleRecord* v = session.find(id);
    ASSERT_NE(v, nullptr);
    const double floor_mps = FLOOR_SHARE * std::min(v->max_speed_mps, libsumo::Vehicle::getAllowedSpeed(id));
    if (!v->guard.handed_back || v->speed_mps < floor_mps) continue;
    EXPECT_DOUBLE_EQ(libsumo::Vehicle::getAccel(id), BOUND_MPS2) << "t " << session.timeS() << ", x " << v->x_m;
    ++held_steps;
  }
  EXPECT_GE(held_steps, 10) << id << " left the busy zones' mainline too soon to tell";
  bool released = false;
  for (int i = 0; i < 200 && !released; ++i) {
    session.step();
    const VehicleRecord* v = session.find(id);
    ASSERT_NE(v, nullptr);
    released = !v->guard.busy_change_bounded;
  }
  EXPECT_TRUE(released) << id << " still bounded 20 s after its change";
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getAccel(id), own_accel) << id << ": its own accel back";
  EXPECT_GT(session.guardCounters().busy_change_bound_steps, 0u);

  // Below the floor it gets going at its own rate: a crawling CAV changing lanes is not bounded.
  std::string slow;
  for (int i = 0; i < 300 && slow.empty(); ++i) {
    session.step();
    slow = pickCav(session);
  }
  ASSERT_FALSE(slow.empty());
  libsumo::Vehicle::slowDown(slow, 2.0, 4.0);  // gently: the traffic behind it brakes in time
  for (int i = 0; i < 45; ++i) session.step();
  ASSERT_NE(session.find(slow), nullptr);
  libsumo::Vehicle::setSpeed(slow, 2.0);
  const int slow_lane = session.find(slow)->lane;
  libsumo::Vehicle::changeLane(slow, session.find(slow)->sumo_lane_index + 1, 5.0);
  for (int i = 0; i < 50; ++i) {
    session.step();
    const VehicleRecord* v = session.find(slow);
    ASSERT_NE(v, nullptr);
    EXPECT_FALSE(v->guard.busy_change_bounded) << slow << " at " << v->speed_mps << " m/s, lane " << v->lane
                                         << " (from " << slow_lane << ")";
  }
}
