// The advice guard (GuardOptions::floor_speed_share) on the tiny road, in-process.
// The self-made jams of issue 18 came from ACCELERATE and the advised-change acceleration
// bound holding CAVs below what their own car following would do: a queued CAV advised a
// small positive acceleration left the queue at that rate, not its own, so a queue drained
// slower than it filled. With the guard a CAV below the floor drives itself, and advice
// cannot brake a CAV below the floor; and a CAV that just changed lanes is not sent back for
// no need of its route (the cooldown). One libsumo simulation per process: one test.
#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <algorithm>
#include <cmath>

#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
constexpr int LANE_LEFT = 0, LANE_RIGHT = 1, ACCELERATE = 2;
constexpr double FLOOR_SHARE = 0.6;

// A mainline CAV in lane 1 or 2 (it can be advised LEFT) with nobody within 100 m ahead of it, or only a fast leader more
// than 30 m ahead, so that the advice (and not a leader) decides its speed; "" when there is
// none this step.
std::string freeCav(const SumoSession& session, double min_speed_mps, double max_speed_mps) {
  for (const VehicleRecord& v : session.vehicles()) {
    if (v.part != RoadPart::kMainline || v.lane < 1 || v.lane > 2 || v.x_m > 200.0 || v.x_m < 20.0 ||
        v.speed_mps < min_speed_mps || v.speed_mps > max_speed_mps || v.lane_change_target != 0)
      continue;
    const auto leader = libsumo::Vehicle::getLeader(v.id, 100.0);
    if (leader.first.empty() || (leader.second > 30.0 && libsumo::Vehicle::getSpeed(leader.first) > 25.0))
      return v.id;
  }
  return "";
}

std::string waitForFreeCav(SumoSession& session, double min_speed_mps, double max_speed_mps = 100.0) {
  std::string id;
  for (int i = 0; i < 3000 && id.empty(); ++i) {
    session.step();
    id = freeCav(session, min_speed_mps, max_speed_mps);
  }
  return id;
}
}  // namespace

TEST(AdviceGuard, AdviceNeverHoldsACavBelowTheFloorAndASlowCavDrivesItself) {
  SessionOptions options = palcas::sim::test::sessionOnTiny("advice_guard", 5);
  options.guard.floor_speed_share = FLOOR_SHARE;
  options.lane_change_max_accel_mps2 = 1.0;  // an advised change's bound, lifted when slow
  options.guard.lane_change_cooldown_s = 10.0;
  options.guard.busy_speed_share = 0.3;  // part 5: busy below 30 % of their top speeds
  options.guard.busy_leave_share = 0.5;
  options.guard.busy_window_s = 1.0;
  options.guard.busy_handback = false;  // busy zones only refuse weaving (busy_handback_test)
  options.guard.insertion_edge = false;  // its own test: insertion_guard_test
  SumoSession session(options);

  // 1. Braking advice stops at the floor: -1.47 m/s^2 held for 12 s would take a CAV from
  // its cruising speed to a crawl (without the guard: 17.6 m/s less).
  const std::string braker = waitForFreeCav(session, 25.0);
  ASSERT_FALSE(braker.empty()) << "no free fast CAV";
  const double floor = session.guardFloorMps(*session.find(braker));
  ASSERT_NEAR(floor, FLOOR_SHARE * std::min(session.find(braker)->max_speed_mps,
                                            libsumo::Vehicle::getAllowedSpeed(braker)), 1e-9);
  double lowest = 1e9;
  for (int i = 0; i < 120 && session.find(braker); ++i) {
    if (i % 10 == 0) session.applyAdvisory(braker, ACCELERATE, -1.47);  // re-advised each second
    session.step();
    if (session.find(braker) && session.find(braker)->part == RoadPart::kMainline)
      lowest = std::min(lowest, session.find(braker)->speed_mps);
  }
  EXPECT_GE(lowest, floor - 0.2) << braker << " was braked below the floor " << floor;
  EXPECT_GT(session.guardCounters().accelerate_floored_steps, 0u);
  session.endCommand(braker);

  // 2. A slow CAV (a queue's, here slowed by the test itself) advised a small positive
  // acceleration speeds up at its own car following's rate, not the advised 0.3 m/s^2.
  const std::string slow = waitForFreeCav(session, 20.0);
  ASSERT_FALSE(slow.empty()) << "no free CAV to slow down";
  libsumo::Vehicle::slowDown(slow, 5.0, 3.0);  // as a queue would
  for (int i = 0; i < 40 && session.find(slow); ++i) session.step();
  ASSERT_NE(session.find(slow), nullptr);
  libsumo::Vehicle::setSpeed(slow, -1.0);  // the test's slowdown ends; its own model again
  const double v0 = session.find(slow)->speed_mps;
  ASSERT_LT(v0, session.guardFloorMps(*session.find(slow)) - 5.0);
  for (int i = 0; i < 20 && session.find(slow); ++i) {
    if (i % 10 == 0) session.applyAdvisory(slow, ACCELERATE, 0.3);
    session.step();
  }
  ASSERT_NE(session.find(slow), nullptr);
  // Its own rate is SUMO's accel 2.6 m/s^2 (less as it nears its desired speed); the advice
  // alone would give 0.6 m/s in these 2 s.
  EXPECT_GT(session.find(slow)->speed_mps - v0, 3.0) << slow << " was held to the advised rate";
  EXPECT_GT(session.guardCounters().accelerate_released_steps, 0u);

  // 3. A slow CAV's advised lane change runs at its own acceleration; a fast one's bounded.
  libsumo::Vehicle::slowDown(slow, 5.0, 2.0);
  for (int i = 0; i < 25 && session.find(slow); ++i) session.step();
  ASSERT_NE(session.find(slow), nullptr);
  libsumo::Vehicle::setSpeed(slow, -1.0);
  const double own_accel = libsumo::Vehicle::getAccel(slow);
  ASSERT_GT(own_accel, 1.0);
  session.applyAdvisory(slow, LANE_LEFT, 0.0);
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getAccel(slow), own_accel) << "bounded below the floor";
  EXPECT_GT(session.guardCounters().lane_change_released_steps, 0u);
  const std::string fast = waitForFreeCav(session, 24.0);  // above any floor of this road
  ASSERT_FALSE(fast.empty());
  session.applyAdvisory(fast, LANE_LEFT, 0.0);
  EXPECT_DOUBLE_EQ(libsumo::Vehicle::getAccel(fast), 1.0) << "a fast CAV's change is bounded";
  EXPECT_GE(session.guardCounters().lane_change_steps,
            session.guardCounters().lane_change_released_steps);

  // 4. The cooldown: a CAV that just changed lanes is not sent back for no need of its route
  // (weaving); a change towards its exit still goes through.
  auto changeLeft = [&](bool exiting) -> std::string {
    for (int tries = 0; tries < 40; ++tries) {
      std::string id;
      for (int i = 0; i < 3000 && id.empty(); ++i) {
        session.step();
        for (const VehicleRecord& v : session.vehicles())
          if (v.part == RoadPart::kMainline && v.lane == 1 && v.x_m > 20.0 && v.x_m < 120.0 &&
              v.lane_change_target == 0 && v.id != slow && v.id != fast && v.id != braker &&
              std::isfinite(v.distance_to_exit_m) == exiting && v.distance_to_exit_m > 150.0)
            id = v.id;
      }
      if (id.empty()) return "";
      session.applyAdvisory(id, LANE_LEFT, 0.0);
      for (int i = 0; i < 25 && session.find(id) && session.find(id)->lane != 2; ++i) session.step();
      if (!session.find(id) || session.find(id)->lane != 2) continue;  // no gap: another one
      session.step();  // the change is seen done
      if (session.find(id)) return id;
    }
    return "";
  };
  const std::string through = changeLeft(false);
  ASSERT_FALSE(through.empty()) << "no through CAV changed to lane 2";
  const auto before = session.guardCounters().lane_changes_cooled_down;
  session.applyAdvisory(through, LANE_RIGHT, 0.0);
  EXPECT_EQ(session.find(through)->lane_change_target, 0) << "sent back within the cooldown";
  EXPECT_EQ(session.guardCounters().lane_changes_cooled_down, before + 1);
  const std::string exiting = changeLeft(true);
  ASSERT_FALSE(exiting.empty()) << "no exiting CAV changed to lane 2";
  session.applyAdvisory(exiting, LANE_RIGHT, 0.0);
  EXPECT_EQ(session.find(exiting)->lane_change_target, 1) << "its way to the exit was refused";
  EXPECT_EQ(session.guardCounters().lane_changes_cooled_down, before + 1);

  // 5. A busy zone: its traffic slowed to a crawl (the test slows every vehicle in zone 0),
  // its CAVs drive themselves, a through CAV's change for speed gain is not carried out there,
  // an exiting one's is.
  for (int i = 0; i < 60; ++i) {
    for (const VehicleRecord& v : session.vehicles())
      if (v.part == RoadPart::kMainline && v.x_m < 300.0) libsumo::Vehicle::slowDown(v.id, 2.0, 0.5);
    session.step();
  }
  EXPECT_TRUE(session.zoneBusy(0)) << "zone 0 at 2 m/s is not busy: share " << session.zoneSpeedShare(0);
  EXPECT_FALSE(session.zoneBusy(1)) << "zone 1 was not slowed: share " << session.zoneSpeedShare(1);
  std::string slow_through, slow_exiting;
  for (const VehicleRecord& v : session.vehicles()) {
    if (v.part != RoadPart::kMainline || v.x_m >= 280.0 || v.lane_change_target != 0 || v.lane < 2) continue;
    if (!std::isfinite(v.distance_to_exit_m) && slow_through.empty()) slow_through = v.id;
    if (std::isfinite(v.distance_to_exit_m) && slow_exiting.empty()) slow_exiting = v.id;
  }
  ASSERT_FALSE(slow_through.empty() || slow_exiting.empty()) << "no through and exiting CAVs in lanes 2-3 of zone 0";
  // There advice slows nobody: the floor is the CAV's allowed speed itself.
  EXPECT_NEAR(session.guardFloorMps(*session.find(slow_through)),
              std::min(session.find(slow_through)->max_speed_mps, libsumo::Vehicle::getAllowedSpeed(slow_through)), 1e-9);
  const auto refused = session.guardCounters().lane_changes_busy_refused;
  if (session.find(slow_through)->lane < 3) {
    session.applyAdvisory(slow_through, LANE_LEFT, 0.0);
    EXPECT_EQ(session.find(slow_through)->lane_change_target, 0) << "weaving in a busy zone";
    EXPECT_EQ(session.guardCounters().lane_changes_busy_refused, refused + 1);
  }
  session.applyAdvisory(slow_exiting, LANE_RIGHT, 0.0);
  EXPECT_EQ(session.find(slow_exiting)->lane_change_target, session.find(slow_exiting)->lane - 1)
      << "its way to the exit was refused in a busy zone";
  EXPECT_GT(session.guardCounters().busy_zone_steps, 0u);
}
