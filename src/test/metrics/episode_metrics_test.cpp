// EpisodeMetricsAccumulator on hand-built samples and event streams; every expected value is
// worked out in the comment next to it.
#include "palcas_core/metrics/episode_metrics.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace palcas::metrics;

namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

VehicleEvent ev(const std::string& id, bool cav, VehicleEventKind kind,
                RouteKind route = RouteKind::kMainThrough) {
  return {id, cav, kind, route, 0, 100.0};
}

/// DEPARTED for each id with the given CAV flag and route.
void depart(EpisodeMetricsAccumulator& acc, const std::vector<std::string>& ids, bool cav,
            RouteKind route) {
  for (const auto& id : ids) acc.addEvent(ev(id, cav, VehicleEventKind::kDeparted, route));
}

}  // namespace

TEST(EpisodeMetrics, EmptyDenominatorsAreNaN) {
  const auto m = EpisodeMetricsAccumulator().snapshot();
  EXPECT_TRUE(std::isnan(m.efficiency_all_mps));
  EXPECT_TRUE(std::isnan(m.efficiency_cav_mps));
  EXPECT_TRUE(std::isnan(m.collision_rate_pct));
  EXPECT_TRUE(std::isnan(m.dsr_pct));
  EXPECT_TRUE(std::isnan(m.msr_pct));
  EXPECT_TRUE(std::isnan(m.comfort_share_pct));
  EXPECT_TRUE(std::isnan(m.throughput_vph));        // no simulated time
  EXPECT_TRUE(std::isnan(m.mean_travel_time_s));    // nobody arrived
  EXPECT_TRUE(std::isnan(m.lane_changes_per_cav));  // no CAV seen
  EXPECT_EQ(m.cavs_seen, 0u);
  EXPECT_EQ(m.vehicles_on_road, 0u);
}

TEST(EpisodeMetrics, CavRatesAreNaNWithOnlyHumanDrivers) {
  EpisodeMetricsAccumulator acc;
  acc.addSample(false, 20.0, 0.0);
  depart(acc, {"h"}, false, RouteKind::kRampExit);
  acc.addEvent(ev("h", false, VehicleEventKind::kMergeOk, RouteKind::kRampExit));
  const auto m = acc.snapshot();
  EXPECT_DOUBLE_EQ(m.efficiency_all_mps, 20.0);
  EXPECT_TRUE(std::isnan(m.efficiency_cav_mps));
  EXPECT_TRUE(std::isnan(m.comfort_share_pct));
  EXPECT_TRUE(std::isnan(m.collision_rate_pct));  // 0 CAVs seen
  EXPECT_TRUE(std::isnan(m.msr_pct));             // a CHV's merge is not counted
  EXPECT_EQ(m.merging_cavs, 0u);
}

TEST(EpisodeMetrics, EfficiencyIsTheMeanOverAllSamples) {
  EpisodeMetricsAccumulator acc;
  acc.addSample(false, 20.0, 0.0);
  acc.addSample(false, 30.0, 0.0);
  acc.addSamples({{true, 10.0, 0.5}, {true, 25.0, -0.5}});
  const auto m = acc.snapshot();
  EXPECT_DOUBLE_EQ(m.efficiency_all_mps, 21.25);  // (20 + 30 + 10 + 25) / 4 = 85 / 4
  EXPECT_DOUBLE_EQ(m.efficiency_cav_mps, 17.5);   // (10 + 25) / 2
}

TEST(EpisodeMetrics, ComfortShareCountsCavSamplesWithinThreshold) {
  EpisodeMetricsAccumulator acc;
  // CAV accelerations 1.47 (in, bound inclusive), -1.47 (in), 1.48 (out), -3 (out), 0 (in).
  for (double a : {1.47, -1.47, 1.48, -3.0, 0.0}) acc.addSample(true, 20.0, a);
  acc.addSample(false, 20.0, 5.0);  // human driver: not in the comfort share
  EXPECT_DOUBLE_EQ(acc.snapshot().comfort_share_pct, 60.0);  // 3 / 5 * 100
}

TEST(EpisodeMetrics, CollisionRateIsPercentOfCavsSeen) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"c1", "c2", "c3", "c4"}, true, RouteKind::kMainThrough);
  depart(acc, {"h1", "h2"}, false, RouteKind::kMainThrough);
  acc.addEvent(ev("c2", true, VehicleEventKind::kCollision));
  acc.addEvent(ev("h1", false, VehicleEventKind::kCollision));
  const auto m = acc.snapshot();
  EXPECT_EQ(m.cavs_seen, 4u);
  EXPECT_EQ(m.collisions, 2u);      // c2 and h1
  EXPECT_EQ(m.cav_collisions, 1u);  // c2
  EXPECT_DOUBLE_EQ(m.collision_rate_pct, 25.0);  // 1 / 4 * 100
  EXPECT_EQ(m.vehicles_on_road, 4u);             // 6 departed - 2 removed
}

TEST(EpisodeMetrics, DsrCountsDecidedExitingCavsOnly) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"ok", "miss", "crash", "open"}, true, RouteKind::kMainExit);
  depart(acc, {"human"}, false, RouteKind::kMainExit);
  depart(acc, {"through"}, true, RouteKind::kMainThrough);
  acc.addEvent(ev("ok", true, VehicleEventKind::kExitOk, RouteKind::kMainExit));
  acc.addEvent(ev("miss", true, VehicleEventKind::kExitMissed, RouteKind::kMainExit));
  acc.addEvent(ev("crash", true, VehicleEventKind::kCollision, RouteKind::kMainExit));
  acc.addEvent(ev("human", false, VehicleEventKind::kExitOk, RouteKind::kMainExit));
  const auto m = acc.snapshot();
  // Decided exiting CAVs: ok, miss, crash (removed before its exit); "open" is undecided.
  EXPECT_EQ(m.exiting_cavs, 3u);
  EXPECT_EQ(m.exits_ok, 1u);
  EXPECT_EQ(m.exits_missed, 1u);
  EXPECT_NEAR(m.dsr_pct, 100.0 / 3.0, 1e-12);  // 1 / 3 * 100 = 33.33...
}

TEST(EpisodeMetrics, MsrCountsDecidedMergingCavsOnly) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"g", "stop", "tele", "late_crash", "open"}, true, RouteKind::kRampThrough);
  acc.addEvent(ev("g", true, VehicleEventKind::kMergeOk, RouteKind::kRampThrough));
  acc.addEvent(ev("stop", true, VehicleEventKind::kMergeFailed, RouteKind::kRampThrough));
  acc.addEvent(ev("stop", true, VehicleEventKind::kMergeOk, RouteKind::kRampThrough));  // too late
  acc.addEvent(ev("tele", true, VehicleEventKind::kTeleport, RouteKind::kRampThrough));
  acc.addEvent(ev("late_crash", true, VehicleEventKind::kMergeOk, RouteKind::kRampThrough));
  acc.addEvent(ev("late_crash", true, VehicleEventKind::kCollision, RouteKind::kRampThrough));
  const auto m = acc.snapshot();
  // Decided: g ok, stop failed, tele failed (removed before merging), late_crash ok.
  EXPECT_EQ(m.merging_cavs, 4u);
  EXPECT_EQ(m.merges_ok, 2u);
  EXPECT_DOUBLE_EQ(m.msr_pct, 50.0);  // 2 / 4 * 100
  EXPECT_EQ(m.teleports, 1u);
  EXPECT_EQ(m.collisions, 1u);
  EXPECT_EQ(acc.ignoredEvents(), 1u);  // the late MERGE_OK of "stop"
}

TEST(EpisodeMetrics, ArrivalWithOpenOutcomesCountsAsMissedAndFailed) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"r"}, true, RouteKind::kRampExit);
  acc.addEvent(ev("r", true, VehicleEventKind::kArrived, RouteKind::kRampExit));
  const auto m = acc.snapshot();
  EXPECT_EQ(m.exiting_cavs, 1u);
  EXPECT_EQ(m.exits_missed, 1u);
  EXPECT_EQ(m.merging_cavs, 1u);
  EXPECT_EQ(m.merges_ok, 0u);
  EXPECT_DOUBLE_EQ(m.dsr_pct, 0.0);
  EXPECT_DOUBLE_EQ(m.msr_pct, 0.0);
}

TEST(EpisodeMetrics, FirstDecidedOutcomeWins) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"a"}, true, RouteKind::kMainExit);
  acc.addEvent(ev("a", true, VehicleEventKind::kExitOk, RouteKind::kMainExit));
  acc.addEvent(ev("a", true, VehicleEventKind::kExitMissed, RouteKind::kMainExit));
  acc.addEvent(ev("a", true, VehicleEventKind::kExitOk, RouteKind::kMainExit));
  const auto m = acc.snapshot();
  EXPECT_EQ(m.exiting_cavs, 1u);
  EXPECT_EQ(m.exits_ok, 1u);
  EXPECT_EQ(m.exits_missed, 0u);
  EXPECT_EQ(acc.ignoredEvents(), 2u);
}

TEST(EpisodeMetrics, EventsOfUnknownVehiclesAreIgnoredAndCounted) {
  EpisodeMetricsAccumulator acc;
  acc.addEvent(ev("ghost", true, VehicleEventKind::kCollision));       // never departed
  depart(acc, {"a"}, true, RouteKind::kMainThrough);
  depart(acc, {"a"}, true, RouteKind::kMainThrough);                   // second DEPARTED
  acc.addEvent(ev("a", true, VehicleEventKind::kArrived));
  acc.addEvent(ev("a", true, VehicleEventKind::kCollision));           // after its removal
  acc.addEvent(ev("b", true, VehicleEventKind::kDeparted));
  acc.addEvent(ev("b", true, VehicleEventKind::kExitOk));              // route has no exit
  const auto m = acc.snapshot();
  EXPECT_EQ(m.cavs_seen, 2u);       // a, b
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_EQ(m.exiting_cavs, 0u);
  EXPECT_EQ(acc.ignoredEvents(), 4u);  // ghost, second DEPARTED, late collision, exit of b
}

TEST(EpisodeMetrics, RegisteredFactsWinOverLaterEvents) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"h"}, false, RouteKind::kMainExit);
  // A later event claiming CAV does not make h a CAV.
  acc.addEvent(ev("h", true, VehicleEventKind::kCollision, RouteKind::kMainExit));
  const auto m = acc.snapshot();
  EXPECT_EQ(m.collisions, 1u);
  EXPECT_EQ(m.cav_collisions, 0u);
}

TEST(EpisodeMetrics, BridgeCounters) {
  EpisodeMetricsAccumulator acc;
  acc.addAdvisoriesApplied(3);
  acc.addAdvisoriesApplied();
  acc.addAdvisoryRejected(RejectionReason::kDuplicate);
  acc.addAdvisoryRejected(RejectionReason::kDuplicate);
  acc.addAdvisoryRejected(RejectionReason::kNoSuchLane);
  acc.addLateRsuStep();
  acc.setSimSeconds(12.5);
  const auto m = acc.snapshot();
  EXPECT_EQ(m.advisories_applied, 4u);   // 3 + 1
  EXPECT_EQ(m.advisories_rejected, 3u);  // 2 + 1
  EXPECT_EQ(acc.rejections(RejectionReason::kDuplicate), 2u);
  EXPECT_EQ(acc.rejections(RejectionReason::kNoSuchLane), 1u);
  EXPECT_EQ(acc.rejections(RejectionReason::kNotACav), 0u);
  EXPECT_EQ(m.late_rsu_steps, 1u);
  EXPECT_DOUBLE_EQ(m.sim_seconds, 12.5);
}

TEST(EpisodeMetrics, RejectsBadCountersAndTimesKeepingState) {
  EpisodeMetricsAccumulator acc;
  acc.setSimSeconds(5.0);
  EXPECT_THROW(acc.setSimSeconds(NaN), std::invalid_argument);
  EXPECT_THROW(acc.setSimSeconds(4.9), std::invalid_argument);  // time runs forward
  EXPECT_THROW(acc.setSimSeconds(INF), std::invalid_argument);
  EXPECT_DOUBLE_EQ(acc.snapshot().sim_seconds, 5.0);
  EXPECT_THROW(acc.addAdvisoryRejected(static_cast<RejectionReason>(REJECTION_REASON_COUNT)),
               std::invalid_argument);
  EXPECT_EQ(acc.snapshot().advisories_rejected, 0u);
}

TEST(EpisodeMetrics, RejectsBadSamplesAtomically) {
  struct Row {
    const char* name;
    SpeedSample sample;
    const char* field;
  };
  const std::vector<Row> rows = {{"nan speed", {true, NaN, 0.0}, "speed_mps"},
                                 {"infinite speed", {false, INF, 0.0}, "speed_mps"},
                                 {"negative speed", {true, -1.0, 0.0}, "speed_mps"},
                                 {"nan accel", {true, 10.0, NaN}, "accel_mps2"},
                                 {"infinite accel", {true, 10.0, -INF}, "accel_mps2"}};
  for (const auto& r : rows) {
    SCOPED_TRACE(r.name);
    EpisodeMetricsAccumulator acc;
    acc.addSample(true, 10.0, 0.0);
    // The good first sample is not added.
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&] { acc.addSamples({{true, 30.0, 0.0}, r.sample}); }, r.field);
    EXPECT_THROW(acc.addSample(r.sample.is_cav, r.sample.speed_mps, r.sample.accel_mps2),
                 std::invalid_argument);
    EXPECT_DOUBLE_EQ(acc.snapshot().efficiency_all_mps, 10.0);  // still only the first sample
  }
}

TEST(EpisodeMetrics, RejectsBadEventsAtomically) {
  struct Row {
    const char* name;
    VehicleEvent event;
    const char* field;
  };
  const std::vector<Row> rows = {
      {"empty id", ev("", true, VehicleEventKind::kCollision), "vehicle_id"},
      {"kind 9", ev("a", true, static_cast<VehicleEventKind>(9)), "kind"},
      {"route 5", ev("a", true, VehicleEventKind::kCollision, static_cast<RouteKind>(5)),
       "route_kind"}};
  for (const auto& r : rows) {
    SCOPED_TRACE(r.name);
    EpisodeMetricsAccumulator acc;
    depart(acc, {"a"}, true, RouteKind::kMainThrough);
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&] { acc.addEvents({ev("a", true, VehicleEventKind::kCollision), r.event}); }, r.field);
    EXPECT_THROW(acc.addEvent(r.event), std::invalid_argument);
    const auto m = acc.snapshot();
    EXPECT_EQ(m.collisions, 0u);  // the valid first event was not applied either
    EXPECT_EQ(m.vehicles_on_road, 1u);
  }
}

TEST(EpisodeMetrics, RejectsBadOptions) {
  EXPECT_THROW(EpisodeMetricsAccumulator({NaN}), std::invalid_argument);
  EXPECT_THROW(EpisodeMetricsAccumulator({-1.0}), std::invalid_argument);
}

TEST(EpisodeMetrics, ComfortThresholdIsAnOption) {
  EpisodeMetricsAccumulator acc({2.0});
  acc.addSample(true, 10.0, 1.9);
  acc.addSample(true, 10.0, 2.1);
  EXPECT_DOUBLE_EQ(acc.snapshot().comfort_share_pct, 50.0);  // 1 / 2 * 100 (1.9 <= 2 < 2.1)
}

TEST(EpisodeMetrics, ResetStartsAFreshEpisode) {
  EpisodeMetricsAccumulator acc({2.0});
  acc.addSample(true, 10.0, 0.0);
  depart(acc, {"a"}, true, RouteKind::kMainThrough);
  acc.addEvent(ev("ghost", true, VehicleEventKind::kArrived));
  acc.addAdvisoryRejected(RejectionReason::kStaleStep);
  acc.setSimSeconds(30.0);
  acc.reset();
  auto m = acc.snapshot();
  EXPECT_TRUE(std::isnan(m.efficiency_all_mps));
  EXPECT_EQ(m.cavs_seen, 0u);
  EXPECT_EQ(m.vehicles_on_road, 0u);
  EXPECT_EQ(m.advisories_rejected, 0u);
  EXPECT_EQ(acc.ignoredEvents(), 0u);
  acc.setSimSeconds(1.0);  // time may start again after a reset
  acc.addSample(true, 10.0, 1.9);
  m = acc.snapshot();
  EXPECT_DOUBLE_EQ(m.comfort_share_pct, 100.0);  // threshold 2.0 kept: 1.9 <= 2
}

TEST(EpisodeMetrics, ThroughputAndTravelTimeCountNormalArrivalsOnly) {
  EpisodeMetricsAccumulator acc;
  acc.setSimSeconds(10.0);
  depart(acc, {"a", "b"}, false, RouteKind::kMainThrough);
  depart(acc, {"x"}, true, RouteKind::kMainExit);
  acc.setSimSeconds(40.0);
  depart(acc, {"c", "crash"}, true, RouteKind::kMainThrough);
  acc.setSimSeconds(70.0);
  acc.addEvent(ev("a", false, VehicleEventKind::kArrived));  // 70 - 10 = 60 s
  acc.addEvent(ev("x", true, VehicleEventKind::kArrived, RouteKind::kMainExit));  // 60 s, off-ramp end
  acc.setSimSeconds(100.0);
  acc.addEvent(ev("c", true, VehicleEventKind::kArrived));           // 100 - 40 = 60 s ...
  acc.addEvent(ev("crash", true, VehicleEventKind::kCollision));     // not an arrival
  acc.addEvent(ev("b", false, VehicleEventKind::kTeleport));         // not an arrival
  acc.setSimSeconds(120.0);
  auto m = acc.snapshot();
  EXPECT_EQ(m.arrived, 3u);                          // a, x, c
  EXPECT_DOUBLE_EQ(m.throughput_vph, 90.0);          // 3600 * 3 / 120
  EXPECT_DOUBLE_EQ(m.mean_travel_time_s, 60.0);      // (60 + 60 + 60) / 3
  depart(acc, {"d"}, false, RouteKind::kMainThrough);  // at 120
  acc.setSimSeconds(240.0);
  acc.addEvent(ev("d", false, VehicleEventKind::kArrived));  // 240 - 120 = 120 s
  m = acc.snapshot();
  EXPECT_DOUBLE_EQ(m.throughput_vph, 60.0);          // 3600 * 4 / 240
  EXPECT_DOUBLE_EQ(m.mean_travel_time_s, 75.0);      // (60 * 3 + 120) / 4
}

TEST(EpisodeMetrics, LaneChangesPerCavCountMainlineLaneChangesOfCavs) {
  EpisodeMetricsAccumulator acc;
  depart(acc, {"c1", "c2", "c3", "c4"}, true, RouteKind::kMainThrough);
  depart(acc, {"ramp"}, true, RouteKind::kRampExit);
  depart(acc, {"h"}, false, RouteKind::kMainThrough);
  // c1: 2 -> 3 -> 3 -> 2: two changes. c2: stays in 1. c3: 1 -> 2 -> 3 in one go of two
  // steps: two changes. c4 never seen on a lane. ramp: 0 (acceleration lane) -> 1 (a merge,
  // not a change) -> 0 (off-ramp, not a change). h: 1 -> 2, a human driver: not counted.
  const std::vector<std::vector<LaneSample>> steps = {
      {{"c1", 2}, {"c2", 1}, {"c3", 1}, {"ramp", 0}, {"h", 1}},
      {{"c1", 3}, {"c2", 1}, {"c3", 2}, {"ramp", 1}, {"h", 2}},
      {{"c1", 3}, {"c2", 1}, {"c3", 3}, {"ramp", 0}},
      {{"c1", 2}, {"c2", 1}, {"ghost", 4}}};  // an unknown vehicle is skipped
  for (const auto& step : steps) acc.addLaneSamples(step);
  auto m = acc.snapshot();
  EXPECT_EQ(m.cav_lane_changes, 4u);                 // c1 2 + c3 2
  EXPECT_DOUBLE_EQ(m.lane_changes_per_cav, 0.8);     // 4 / 5 CAVs seen
  // Off the mainline and back to another lane: the change still counts (last lane 2 -> 1).
  acc.addLaneSamples({{"c1", 0}});
  acc.addLaneSamples({{"c1", 1}});
  m = acc.snapshot();
  EXPECT_EQ(m.cav_lane_changes, 5u);
  EXPECT_DOUBLE_EQ(m.lane_changes_per_cav, 1.0);     // 5 / 5
  // A removed vehicle starts afresh if its id comes back: no change against its old lane.
  acc.addEvent(ev("c2", true, VehicleEventKind::kArrived));
  depart(acc, {"c2"}, true, RouteKind::kMainThrough);
  acc.addLaneSamples({{"c2", 3}});
  EXPECT_EQ(acc.snapshot().cav_lane_changes, 5u);
  EXPECT_THROW(acc.addLaneSamples({{"c1", 2}, {"c3", -1}}), std::invalid_argument);
  EXPECT_EQ(acc.snapshot().cav_lane_changes, 5u);    // c1's good sample was not added
}

TEST(EpisodeMetrics, SteadyStateSpeedCountsOnlySamplesFromItsStartOn) {
  EpisodeMetricsOptions o;
  o.steady_state_from_s = 10.0;
  EpisodeMetricsAccumulator acc(o);
  acc.addSample(false, 30.0, 0.0);  // t = 0: before the window
  acc.setSimSeconds(5.0);
  acc.addSample(false, 28.0, 0.0);  // sampled after t = 5: still before
  acc.setSimSeconds(10.0);
  acc.addSamples({{false, 12.0, 0.0}, {true, 18.0, 0.0}});  // after t = 10: in
  acc.setSimSeconds(10.1);
  const auto m = acc.snapshot();
  EXPECT_DOUBLE_EQ(m.efficiency_steady_mps, 15.0);  // (12 + 18) / 2
  EXPECT_DOUBLE_EQ(m.efficiency_all_mps, 22.0);     // (30 + 28 + 12 + 18) / 4
  EXPECT_TRUE(std::isnan(EpisodeMetricsAccumulator(o).snapshot().efficiency_steady_mps));
  o.steady_state_from_s = -1.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { EpisodeMetricsAccumulator bad(o); },
                                                        "steady_state_from_s");
}

TEST(EpisodeMetrics, VehicleSecondsCountEachVehicleFromDepartureToRemovalOrTheEnd) {
  EpisodeMetricsAccumulator acc;
  acc.setSimSeconds(1.0);
  depart(acc, {"a", "b"}, false, RouteKind::kMainThrough);  // on the road from t = 1
  acc.setSimSeconds(4.0);                                   // 2 x 3 s
  acc.addEvent(ev("a", false, VehicleEventKind::kArrived));  // a leaves at t = 4
  depart(acc, {"c"}, true, RouteKind::kMainThrough);        // c from t = 4
  acc.setSimSeconds(6.0);                                   // b and c: 2 x 2 s
  EXPECT_DOUBLE_EQ(acc.snapshot().vehicle_seconds_on_road, 10.0);  // 6 + 4
}

TEST(EpisodeMetrics, CensoredCavsCountAgainstTheCensoredRatesOnly) {
  EpisodeMetricsAccumulator acc;
  // Three exit-bound CAVs: one exits, one misses, one is still on the road at the end.
  depart(acc, {"x1", "x2", "x3"}, true, RouteKind::kMainExit);
  acc.addEvent(ev("x1", true, VehicleEventKind::kExitOk, RouteKind::kMainExit));
  acc.addEvent(ev("x2", true, VehicleEventKind::kExitMissed, RouteKind::kMainExit));
  // Two merging CAVs: one merged, one still on its ramp; a merging HDV is not counted.
  depart(acc, {"m1", "m2"}, true, RouteKind::kRampThrough);
  depart(acc, {"h"}, false, RouteKind::kRampThrough);
  acc.addEvent(ev("m1", true, VehicleEventKind::kMergeOk, RouteKind::kRampThrough));
  const auto m = acc.snapshot();
  EXPECT_EQ(m.exiting_cavs, 2u);
  EXPECT_EQ(m.exiting_cavs_censored, 1u);
  EXPECT_DOUBLE_EQ(m.dsr_pct, 50.0);                   // 1 of 2 decided
  EXPECT_DOUBLE_EQ(m.dsr_censored_pct, 100.0 / 3.0);   // 1 of 3
  EXPECT_EQ(m.merging_cavs_censored, 1u);
  EXPECT_DOUBLE_EQ(m.msr_pct, 100.0);                  // 1 of 1 decided
  EXPECT_DOUBLE_EQ(m.msr_censored_pct, 50.0);          // 1 of 2
}
