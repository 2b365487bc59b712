// The guard's hand-back (GuardOptions::busy_handback) on the tiny road, in-process.
// In advisory mode the RSUs alone serve the exits; where a zone's traffic has broken down
// that costs up to 30 % of the road's speed (README "Advice that does no harm"). In a busy
// zone a CAV therefore gets its own route-aware driving back (route to its off-ramp, SUMO's
// lane changes) and its advice is dropped; once the zone is free the RSUs have it again.
// With guard_busy_lc_assertive its gap acceptance is the busy zone's meanwhile.
// One libsumo simulation per process: one test.
#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
constexpr int LANE_LEFT = 0, ACCELERATE = 2;
constexpr int OWN_LANE_CHANGE_MODE = 1621, ADVISED_LANE_CHANGE_MODE = 1536;
constexpr double BUSY_LC_ASSERTIVE = 2.0;

double lcAssertive(const std::string& id) {
  return std::stod(libsumo::Vehicle::getParameter(id, "laneChangeModel.lcAssertive"));
}

bool inZone0(const VehicleRecord& v) {
  return v.part == RoadPart::kMainline && v.lane >= 1 && v.x_m > 5.0 && v.x_m < 295.0;
}

// Its SUMO route ends at its own off-ramp (the last edge of the route it was inserted on).
bool routedToOwnExit(const VehicleRecord& v) {
  return libsumo::Vehicle::getRoute(v.id).back() == libsumo::Route::getEdges(v.route_id).back();
}
}  // namespace

TEST(BusyHandback, ABusyZonesCavsDriveThemselvesAndComeBackWhenItIsFree) {
  SessionOptions options = palcas::sim::test::sessionOnTiny("busy_handback", 7);
  // Busy below 20 % of their top speeds, free again above 30 %: a zone slowed to a crawl
  // refills from a standing queue at the road's start, which keeps its share near 0.4.
  options.guard.busy_speed_share = 0.2;
  options.guard.busy_leave_share = 0.3;
  options.guard.busy_window_s = 1.0;
  options.guard.busy_handback = true;
  options.assist_lane_change_mode = OWN_LANE_CHANGE_MODE;
  options.guard.busy_lc_assertive = BUSY_LC_ASSERTIVE;
  // Advice that runs again at the end may pick any zone-0 CAV, on the warm-up edge too.
  options.guard.insertion_edge = false;
  SumoSession session(options);
  for (int i = 0; i < 600; ++i) session.step();  // the road fills

  // Free traffic: nobody handed back, lane changes are the RSUs'.
  for (const VehicleRecord& v : session.vehicles()) {
    EXPECT_FALSE(v.guard.handed_back) << v.id << " handed back on a free road";
    if (inZone0(v) && !v.merge_mode) { EXPECT_EQ(libsumo::Vehicle::getLaneChangeMode(v.id), ADVISED_LANE_CHANGE_MODE); }
    if (v.is_cav) { EXPECT_DOUBLE_EQ(lcAssertive(v.id), 1.0) << v.id << ": its vType's gap acceptance"; }
  }
  EXPECT_EQ(session.guardCounters().handbacks, 0u);

  // Zone 0's traffic slowed to a crawl (the test slows every vehicle there): it is busy.
  for (int i = 0; i < 60; ++i) {
    for (const VehicleRecord& v : session.vehicles())
      if (v.part == RoadPart::kMainline && v.x_m < 300.0) libsumo::Vehicle::slowDown(v.id, 2.0, 0.5);
    session.step();
  }
  ASSERT_TRUE(session.zoneBusy(0)) << "share " << session.zoneSpeedShare(0);
  ASSERT_FALSE(session.zoneBusy(1)) << "share " << session.zoneSpeedShare(1);
  int handed_back = 0, exiting_handed_back = 0;
  std::string sample;
  for (const VehicleRecord& v : session.vehicles()) {
    if (!inZone0(v) || v.merge_mode) {
      if (v.part == RoadPart::kMainline && v.x_m > 305.0) { EXPECT_FALSE(v.guard.handed_back) << v.id << " in the free zone 1"; }
      continue;
    }
    EXPECT_TRUE(v.guard.handed_back) << v.id << " at x " << v.x_m << " in busy zone 0";
    if (!v.guard.handed_back) continue;
    ++handed_back;
    EXPECT_EQ(libsumo::Vehicle::getLaneChangeMode(v.id), OWN_LANE_CHANGE_MODE) << v.id;
    EXPECT_DOUBLE_EQ(lcAssertive(v.id), BUSY_LC_ASSERTIVE) << v.id << ": the busy zone's gap acceptance";
    if (std::isfinite(v.distance_to_exit_m)) {
      ++exiting_handed_back;
      EXPECT_TRUE(routedToOwnExit(v)) << v.id << " is not routed to its off-ramp";
    }
    if (sample.empty() && v.lane < 3) sample = v.id;
  }
  ASSERT_GT(handed_back, 3) << "too few CAVs in zone 0 to tell";
  EXPECT_GT(exiting_handed_back, 0) << "no exiting CAV in zone 0 to tell";
  EXPECT_GE(session.guardCounters().handbacks, static_cast<unsigned>(handed_back));
  EXPECT_GT(session.guardCounters().handback_steps, 0u);

  // Advice for a handed-back CAV is dropped and counted; bad advice is still refused by name.
  ASSERT_FALSE(sample.empty());
  const auto dropped = session.guardCounters().handback_advice_dropped;
  session.applyAdvisory(sample, LANE_LEFT, 0.0);
  session.applyAdvisory(sample, ACCELERATE, -2.0);
  EXPECT_EQ(session.find(sample)->lane_change_target, 0);
  EXPECT_EQ(session.find(sample)->command, palcas::sim::HeldCommand::kNone);
  EXPECT_EQ(session.guardCounters().handback_advice_dropped, dropped + 2);
  EXPECT_THROW(session.applyAdvisory(sample, ACCELERATE, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);

  // The crawl ends: once zone 0 is free its CAVs are the RSUs' again, routed to the mainline
  // end (the bridge switches an exiting one to its off-ramp in lane 1 before it).
  for (int i = 0; i < 600 && session.zoneBusy(0); ++i) {
    for (const VehicleRecord& v : session.vehicles()) libsumo::Vehicle::setSpeed(v.id, -1.0);
    session.step();
  }
  ASSERT_FALSE(session.zoneBusy(0)) << "share " << session.zoneSpeedShare(0);
  session.step();
  int back = 0;
  for (const VehicleRecord& v : session.vehicles()) {
    if (!inZone0(v) || v.merge_mode) continue;
    EXPECT_FALSE(v.guard.handed_back) << v.id;
    EXPECT_EQ(libsumo::Vehicle::getLaneChangeMode(v.id), ADVISED_LANE_CHANGE_MODE) << v.id;
    EXPECT_DOUBLE_EQ(lcAssertive(v.id), 1.0) << v.id << ": its own gap acceptance back";
    if (std::isfinite(v.distance_to_exit_m) && !v.exit_committed) {
      EXPECT_FALSE(routedToOwnExit(v)) << v.id << " still routed to its off-ramp by SUMO";
      ++back;
    }
  }
  EXPECT_GT(back, 0) << "no exiting CAV in zone 0 to tell";
  // Advice runs again.
  const auto advised = session.guardCounters().lane_changes_advised;
  for (const VehicleRecord& v : session.vehicles())
    if (inZone0(v) && !v.merge_mode && v.lane < 3 && v.lane_change_target == 0) {
      session.applyAdvisory(v.id, LANE_LEFT, 0.0);
      EXPECT_EQ(session.find(v.id)->lane_change_target, v.lane + 1);
      break;
    }
  EXPECT_EQ(session.guardCounters().lane_changes_advised, advised + 1);
}
