// The guard's start (GuardOptions::busy_at_start) on the tiny road, in-process. A road
// that fills near capacity is advised in its first minute while its zones still count as free,
// and that advice set off the breakdown (docs/journal/experiments.md, "Advice while the road
// fills"). With the option on, every zone counts as busy from the start and its CAVs drive
// themselves until the zone has shown that it runs free. One libsumo simulation per process.
#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {
constexpr int ACCELERATE = 2;

bool inZone0(const VehicleRecord& v) {
  return v.is_cav && v.part == RoadPart::kMainline && v.lane >= 1 && v.x_m > 5.0 && v.x_m < 295.0;
}
}  // namespace

TEST(BusyAtStart, ZonesStartBusyAndAreAdvisedOnlyOnceTheyRunFree) {
  SessionOptions options = palcas::sim::test::sessionOnTiny("busy_at_start", 7);
  options.guard.busy_at_start = true;
  options.guard.busy_speed_share = 0.2;  // free traffic runs far above it
  options.guard.busy_leave_share = 0.3;
  options.guard.busy_window_s = 5.0;
  options.guard.busy_handback = true;
  SumoSession session(options);
  session.step();
  for (int k = 0; k < static_cast<int>(session.road().clusters().size()); ++k)
    EXPECT_TRUE(session.zoneBusy(k)) << "zone " << k << " free at the start: share " << session.zoneSpeedShare(k);

  // While zone 0 has not yet shown free running, its CAVs drive themselves: advice is dropped.
  std::string early;
  for (int i = 0; i < 100 && early.empty() && session.zoneBusy(0); ++i) {
    session.step();
    for (const VehicleRecord& v : session.vehicles())
      if (inZone0(v) && !v.merge_mode && v.guard.handed_back) early = v.id;
  }
  ASSERT_FALSE(early.empty()) << "no CAV in zone 0 while it still counted as busy";
  const auto dropped = session.guardCounters().handback_advice_dropped;
  session.applyAdvisory(early, ACCELERATE, 1.0);
  EXPECT_EQ(session.guardCounters().handback_advice_dropped, dropped + 1);

  // Free traffic lifts the smoothed share above the leave share within a few windows: then
  // the zone is the RSUs' and its CAVs are advised again.
  for (int i = 0; i < 1200 && session.zoneBusy(0); ++i) session.step();
  ASSERT_FALSE(session.zoneBusy(0)) << "zone 0 still busy after 2 min of free traffic: share "
                                    << session.zoneSpeedShare(0);
  session.step();
  int advised = 0;
  for (const VehicleRecord& v : session.vehicles()) {
    if (!inZone0(v) || v.merge_mode) continue;
    EXPECT_FALSE(v.guard.handed_back) << v.id << " still handed back in a free zone";
    session.applyAdvisory(v.id, ACCELERATE, 1.0);
    if (session.find(v.id)->command == palcas::sim::HeldCommand::kAccelerate) ++advised;
  }
  EXPECT_GT(advised, 0) << "no CAV in free zone 0 took its advice";
}
