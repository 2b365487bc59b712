// The advice guard where traffic is inserted (GuardOptions::insertion_edge), on the
// tiny road, in-process. Every CAV collision in the shipped policy's evaluation runs (issue
// 18) was on the warm-up edge: SUMO 1.15 inserts mainline vehicles there at a random free
// place at the highest safe speed, and a vehicle inserted beside or just behind a CAV that
// is moving sideways into its lane runs into it (stage=laneChange, lateral gap -0.02 to
// -0.24 m). Here every CAV on the warm-up edge is advised a lane change every step at a busy
// demand. Built twice: with the guard (no collision, the refusals counted) and without it
// (PALCAS_GUARD_OFF: the collisions the guard prevents, so the first cannot pass for want of
// traffic). One libsumo simulation per process: one test per binary.
#include <gtest/gtest.h>

#include <cstdio>
#include <set>
#include <string>

#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"

using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {

constexpr int LANE_LEFT = 0, LANE_RIGHT = 1;

SessionOptions busyTinyRoad(bool guard_on) {
  SessionOptions o = palcas::sim::test::sessionOnTiny(guard_on ? "insertion_on" : "insertion_off", 11, 2000.0);
  o.guard.insertion_edge = guard_on;
  o.guard.busy_speed_share = 0.0;  // busy zones would drop the advice: this test is about insertion
  o.guard.busy_leave_share = 0.0;
  return o;
}

}  // namespace

#ifndef PALCAS_GUARD_OFF
TEST(InsertionGuard, NoAdvisedLaneChangeWhereVehiclesAreInsertedSoNoCollisionThere) {
#else
TEST(InsertionGuard, WithoutTheGuardAdvisedLaneChangesCollideWithInsertedVehicles) {
#endif
#ifndef PALCAS_GUARD_OFF
  const bool guard_on = true;
#else
  const bool guard_on = false;
#endif
  SumoSession session(busyTinyRoad(guard_on));
  std::set<std::string> collided;
  std::size_t advised = 0;
  for (int i = 0; i < 3000; ++i) {
    for (const VehicleRecord& v : session.vehicles()) {
      if (!v.is_cav || v.edge != "main_0_warmup" || v.lane_change_target != 0) continue;
      session.applyAdvisory(v.id, v.lane < 3 ? LANE_LEFT : LANE_RIGHT, 0.0);
      ++advised;
    }
    for (const std::string& id : session.step().collided) collided.insert(id);
  }
  ASSERT_GT(advised, 500u);
  const auto refused = session.guardCounters().lane_changes_insertion_refused;
  if (guard_on) {
    EXPECT_EQ(refused, advised);
    EXPECT_TRUE(collided.empty()) << collided.size() << " vehicles collided";
  } else {
    EXPECT_EQ(refused, 0u);
    EXPECT_GE(collided.size(), 2u) << "the mechanism did not show: no collision without the guard";
    std::printf("without the guard: %zu advised lane changes, %zu vehicles collided\n", advised, collided.size());
  }
}
