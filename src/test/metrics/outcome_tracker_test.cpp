// Scripted episodes for OutcomeTracker (and the VehicleEvent codes it emits). Road used
// throughout: three clusters whose off-ramps leave the mainline at x = 700, 1500, 2300 m.
#include "palcas_core/metrics/outcome_tracker.h"
#include "msg_constants.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "palcas_core/metrics/episode_metrics.h"

using namespace palcas::metrics;

namespace {

constexpr double NaN = std::numeric_limits<double>::quiet_NaN();
constexpr double INF = std::numeric_limits<double>::infinity();

OutcomeTrackerOptions roadOptions() {
  OutcomeTrackerOptions o;
  o.exit_x_m = {700.0, 1500.0, 2300.0};
  return o;  // miss margin 0 m, stop = v < 0.1 m/s within 10 m of the accel-lane end
}

VehicleObservation onMainline(const std::string& id, bool cav, RouteKind route, int exit_cluster,
                              double x_m, double speed_mps = 25.0) {
  VehicleObservation o;
  o.id = id;
  o.is_cav = cav;
  o.route_kind = route;
  o.road_part = RoadPart::kMainline;
  o.exit_cluster = exit_cluster;
  o.x_m = x_m;
  o.speed_mps = speed_mps;
  return o;
}

VehicleObservation onPart(const std::string& id, bool cav, RouteKind route, int exit_cluster,
                          RoadPart part, int cluster, double x_m, double speed_mps = 15.0) {
  VehicleObservation o = onMainline(id, cav, route, exit_cluster, x_m, speed_mps);
  o.road_part = part;
  o.part_cluster = cluster;
  return o;
}

/// On cluster `cluster`'s 200 m acceleration lane at position pos_m.
VehicleObservation onAccelLane(const std::string& id, RouteKind route, int exit_cluster,
                               int cluster, double pos_m, double speed_mps) {
  VehicleObservation o =
      onPart(id, true, route, exit_cluster, RoadPart::kAccelLane, cluster, 100.0 + pos_m,
             speed_mps);
  o.accel_lane_pos_m = pos_m;
  o.accel_lane_length_m = 200.0;
  return o;
}

/// "id:kind" per event, in order, for readable comparisons.
std::vector<std::string> names(const std::vector<VehicleEvent>& events) {
  std::vector<std::string> out;
  for (const auto& e : events) out.push_back(e.vehicle_id + ":" + vehicleEventKindName(e.kind));
  return out;
}

using Names = std::vector<std::string>;

}  // namespace

TEST(OutcomeTracker, DepartedOnFirstSightOnly) {
  OutcomeTracker tracker(roadOptions());
  const auto car = onMainline("a", true, RouteKind::kMainThrough, -1, 50.0);
  EXPECT_EQ(names(tracker.update({car}, {})), Names({"a:departed"}));
  EXPECT_EQ(names(tracker.update({car}, {})), Names({}));
  EXPECT_EQ(tracker.trackedVehicles(), 1u);
}

TEST(OutcomeTracker, SuccessfulExitThenArrival) {
  OutcomeTracker tracker(roadOptions());
  // Exit of cluster 1 at x = 1500 m; at 1400 m on the mainline nothing is decided yet.
  tracker.update({onMainline("e", true, RouteKind::kMainExit, 1, 1400.0)}, {});
  const auto events = tracker.update(
      {onPart("e", true, RouteKind::kMainExit, 1, RoadPart::kOffRamp, 1, 1510.0)}, {});
  ASSERT_EQ(names(events), Names({"e:exit_ok"}));
  EXPECT_EQ(events[0].cluster, 1);
  EXPECT_DOUBLE_EQ(events[0].x_m, 1510.0);
  EXPECT_TRUE(events[0].is_cav);
  EXPECT_EQ(events[0].route_kind, RouteKind::kMainExit);
  // Arrival after a decided exit adds no second exit event, and the vehicle is forgotten.
  EXPECT_EQ(names(tracker.update({}, {{}, {}, {"e"}})), Names({"e:arrived"}));
  EXPECT_EQ(tracker.trackedVehicles(), 0u);
}

TEST(OutcomeTracker, MissedExitWhenPastTheExitOnTheMainline) {
  OutcomeTracker tracker(roadOptions());
  tracker.update({onMainline("m", true, RouteKind::kMainExit, 1, 1400.0)}, {});
  // x = 1500 is the exit itself: not yet past (the rule is x > x_exit + margin = 1500 + 0).
  EXPECT_EQ(names(tracker.update({onMainline("m", true, RouteKind::kMainExit, 1, 1500.0)}, {})),
            Names({}));
  EXPECT_EQ(names(tracker.update({onMainline("m", true, RouteKind::kMainExit, 1, 1503.0)}, {})),
            Names({"m:exit_missed"}));
  // The bridge re-routes it onward: route facts from first sight stay, nothing new is decided.
  EXPECT_EQ(names(tracker.update({onMainline("m", true, RouteKind::kMainThrough, -1, 1600.0)}, {})),
            Names({}));
  EXPECT_EQ(names(tracker.update({}, {{}, {}, {"m"}})), Names({"m:arrived"}));
}

TEST(OutcomeTracker, MissMarginDelaysTheMiss) {
  auto options = roadOptions();
  options.miss_margin_m = 5.0;
  OutcomeTracker tracker(options);
  tracker.update({onMainline("m", true, RouteKind::kMainExit, 0, 650.0)}, {});
  // Exit of cluster 0 at 700 m; 703 <= 700 + 5 = 705: not yet; 706 > 705: missed.
  EXPECT_EQ(names(tracker.update({onMainline("m", true, RouteKind::kMainExit, 0, 703.0)}, {})),
            Names({}));
  EXPECT_EQ(names(tracker.update({onMainline("m", true, RouteKind::kMainExit, 0, 706.0)}, {})),
            Names({"m:exit_missed"}));
}

TEST(OutcomeTracker, LeavingByAnotherOffRampIsAMiss) {
  OutcomeTracker tracker(roadOptions());
  tracker.update({onMainline("w", true, RouteKind::kMainExit, 2, 600.0)}, {});
  // Own exit is cluster 2; seen on cluster 0's off-ramp.
  EXPECT_EQ(names(tracker.update(
                {onPart("w", true, RouteKind::kMainExit, 2, RoadPart::kOffRamp, 0, 710.0)}, {})),
            Names({"w:exit_missed"}));
}

TEST(OutcomeTracker, ArrivalWithoutExitIsAMissAndWithoutMergeAFailure) {
  OutcomeTracker tracker(roadOptions());
  tracker.update({onPart("r", true, RouteKind::kRampExit, 2, RoadPart::kOnRamp, 0, 50.0)}, {});
  EXPECT_EQ(names(tracker.update({}, {{}, {}, {"r"}})),
            Names({"r:merge_failed", "r:exit_missed", "r:arrived"}));
}

TEST(OutcomeTracker, SuccessfulMerge) {
  OutcomeTracker tracker(roadOptions());
  const auto route = RouteKind::kRampThrough;
  EXPECT_EQ(names(tracker.update({onPart("g", true, route, -1, RoadPart::kOnRamp, 0, 60.0)}, {})),
            Names({"g:departed"}));
  // Slow near the end of the lane but not stopped: 0.5 m/s >= 0.1 m/s.
  EXPECT_EQ(names(tracker.update({onAccelLane("g", route, -1, 0, 195.0, 0.5)}, {})), Names({}));
  const auto events = tracker.update({onMainline("g", true, route, -1, 300.0)}, {});
  ASSERT_EQ(names(events), Names({"g:merge_ok"}));
  EXPECT_DOUBLE_EQ(events[0].x_m, 300.0);
}

TEST(OutcomeTracker, StopAtEndOfAccelLaneFailsEvenIfItMergesLater) {
  OutcomeTracker tracker(roadOptions());
  const auto route = RouteKind::kRampExit;
  tracker.update({onAccelLane("s", route, 1, 0, 150.0, 12.0)}, {});
  // 200 - 192 = 8 m <= 10 m from the end and 0.05 < 0.1 m/s: stopped.
  EXPECT_EQ(names(tracker.update({onAccelLane("s", route, 1, 0, 192.0, 0.05)}, {})),
            Names({"s:merge_failed"}));
  EXPECT_EQ(names(tracker.update({onMainline("s", true, route, 1, 310.0)}, {})), Names({}));
}

TEST(OutcomeTracker, StopRuleEdges) {
  OutcomeTracker tracker(roadOptions());
  const auto route = RouteKind::kRampThrough;
  tracker.update(
      {onAccelLane("x", route, -1, 0, 10.0, 5.0), onAccelLane("y", route, -1, 0, 10.0, 5.0)}, {});
  // x: 200 - 189.5 = 10.5 m > 10 m from the end: not in the window although at 0 m/s.
  // y: exactly 0.1 m/s is not below 0.1 m/s.
  EXPECT_EQ(names(tracker.update({onAccelLane("x", route, -1, 0, 189.5, 0.0),
                                  onAccelLane("y", route, -1, 0, 195.0, 0.1)},
                                 {})),
            Names({}));
  // x: 200 - 190 = 10 m, inside the window (<= 10 m).
  EXPECT_EQ(names(tracker.update({onAccelLane("x", route, -1, 0, 190.0, 0.0)}, {})),
            Names({"x:merge_failed"}));
}

TEST(OutcomeTracker, MainlineVehicleOnAccelLaneIsNotAMerge) {
  OutcomeTracker tracker(roadOptions());
  // A mainline-route car that moved right onto an acceleration lane; its cluster unknown (-1).
  auto car = onMainline("m", false, RouteKind::kMainThrough, -1, 120.0, 0.0);
  car.road_part = RoadPart::kAccelLane;
  car.accel_lane_pos_m = 195.0;
  car.accel_lane_length_m = 200.0;
  EXPECT_EQ(names(tracker.update({car}, {})), Names({"m:departed"}));  // stopped, but no merge
  EXPECT_EQ(names(tracker.update({}, {{}, {}, {"m"}})), Names({"m:arrived"}));
}

TEST(OutcomeTracker, CollisionOnAccelLaneFailsTheMerge) {
  OutcomeTracker tracker(roadOptions());
  tracker.update({onAccelLane("c", RouteKind::kRampThrough, -1, 1, 80.0, 14.0)}, {});
  const auto events = tracker.update({}, {{"c"}, {}, {}});
  ASSERT_EQ(names(events), Names({"c:merge_failed", "c:collision"}));
  EXPECT_EQ(events[1].cluster, 1);  // last known place
  EXPECT_DOUBLE_EQ(events[1].x_m, 180.0);
}

TEST(OutcomeTracker, CollisionAfterMergeKeepsTheMergeAndCountsInCr) {
  OutcomeTracker tracker(roadOptions());
  EpisodeMetricsAccumulator metrics;
  metrics.addEvents(tracker.update(
      {onAccelLane("j", RouteKind::kRampThrough, -1, 0, 120.0, 20.0),
       onMainline("k", true, RouteKind::kMainThrough, -1, 100.0)},
      {}));
  metrics.addEvents(
      tracker.update({onMainline("j", true, RouteKind::kRampThrough, -1, 330.0)}, {}));
  const auto events = tracker.update({}, {{"j"}, {}, {}});
  EXPECT_EQ(names(events), Names({"j:collision"}));
  metrics.addEvents(events);
  const auto m = metrics.snapshot();
  EXPECT_EQ(m.merging_cavs, 1u);
  EXPECT_EQ(m.merges_ok, 1u);
  EXPECT_DOUBLE_EQ(m.msr_pct, 100.0);           // 1 / 1
  EXPECT_DOUBLE_EQ(m.collision_rate_pct, 50.0);  // 1 collided CAV / 2 CAVs seen
}

TEST(OutcomeTracker, CollisionBeforeExitIsADsrFailure) {
  OutcomeTracker tracker(roadOptions());
  EpisodeMetricsAccumulator metrics;
  metrics.addEvents(tracker.update({onMainline("d", true, RouteKind::kMainExit, 1, 900.0),
                                    onMainline("h", false, RouteKind::kMainThrough, -1, 890.0)},
                                   {}));
  const auto events = tracker.update({}, {{"d", "h"}, {}, {}});
  // No exit event exists for "removed before the exit"; the accumulator infers it.
  EXPECT_EQ(names(events), Names({"d:collision", "h:collision"}));
  metrics.addEvents(events);
  const auto m = metrics.snapshot();
  EXPECT_EQ(m.collisions, 2u);       // both vehicles involved
  EXPECT_EQ(m.cav_collisions, 1u);   // only d is a CAV
  EXPECT_DOUBLE_EQ(m.collision_rate_pct, 100.0);  // 1 / 1 CAV seen
  EXPECT_EQ(m.exiting_cavs, 1u);
  EXPECT_EQ(m.exits_ok, 0u);
  EXPECT_EQ(m.exits_missed, 0u);     // a failure, but not a miss
  EXPECT_DOUBLE_EQ(m.dsr_pct, 0.0);  // 0 / 1
}

TEST(OutcomeTracker, TeleportIsCountedApartFromCollisions) {
  OutcomeTracker tracker(roadOptions());
  EpisodeMetricsAccumulator metrics;
  metrics.addEvents(tracker.update({onMainline("t", true, RouteKind::kMainExit, 2, 1200.0)}, {}));
  const auto events = tracker.update({}, {{}, {"t"}, {}});
  EXPECT_EQ(names(events), Names({"t:teleport"}));
  metrics.addEvents(events);
  const auto m = metrics.snapshot();
  EXPECT_EQ(m.teleports, 1u);
  EXPECT_EQ(m.collisions, 0u);
  EXPECT_DOUBLE_EQ(m.collision_rate_pct, 0.0);  // 0 / 1 CAV
  EXPECT_EQ(m.exiting_cavs, 1u);                // removed before its exit: DSR failure
  EXPECT_DOUBLE_EQ(m.dsr_pct, 0.0);
}

TEST(OutcomeTracker, TalliesEachExitsCavsByOutcomeAndSumsToTheEpisodesDsr) {
  OutcomeTracker tracker(roadOptions());
  EpisodeMetricsAccumulator metrics;
  auto step = [&](const std::vector<VehicleObservation>& obs, const StepRemovals& removals) {
    metrics.addEvents(tracker.update(obs, removals));
  };
  const auto exit = RouteKind::kMainExit;
  step({onMainline("served0", true, exit, 0, 600.0), onMainline("passed1", true, exit, 1, 1400.0),
        onMainline("elsewhere1", true, exit, 1, 600.0), onMainline("crash2", true, exit, 2, 2000.0),
        onMainline("open2", true, exit, 2, 2100.0), onMainline("arrive2", true, exit, 2, 2200.0),
        onMainline("human0", false, exit, 0, 650.0)},
       {});
  step({onPart("served0", true, exit, 0, RoadPart::kOffRamp, 0, 710.0),
        onMainline("passed1", true, exit, 1, 1501.0),
        onPart("elsewhere1", true, exit, 1, RoadPart::kOffRamp, 0, 710.0),
        onMainline("open2", true, exit, 2, 2150.0),
        onPart("human0", false, exit, 0, RoadPart::kOffRamp, 0, 710.0)},
       {{"crash2"}, {}, {"arrive2"}});
  const std::vector<ExitTally> exits = tracker.cavExits();
  ASSERT_EQ(exits.size(), 3u);  // one per configured exit, a human driver in none
  EXPECT_EQ(exits[0].served, 1u);
  EXPECT_EQ(exits[0].exitBound(), 1u);
  EXPECT_DOUBLE_EQ(exits[0].servedPct(), 100.0);
  EXPECT_EQ(exits[1].missed, 2u);  // passed it on the mainline; left by exit 0's off-ramp
  EXPECT_DOUBLE_EQ(exits[1].servedPct(), 0.0);
  EXPECT_EQ(exits[2].lost, 1u);      // collided before its exit
  EXPECT_EQ(exits[2].missed, 1u);    // arrived without being seen on its off-ramp
  EXPECT_EQ(exits[2].censored, 1u);  // still before its exit
  // The pooled figures the episode reports are these tallies summed.
  const auto m = metrics.snapshot();
  std::size_t served = 0, decided = 0, censored = 0;
  for (const auto& e : exits) {
    served += e.served;
    decided += e.served + e.missed + e.lost;
    censored += e.censored;
  }
  EXPECT_EQ(served, m.exits_ok);
  EXPECT_EQ(decided, m.exiting_cavs);
  EXPECT_EQ(censored, m.exiting_cavs_censored);
  // reset() forgets the tallies with the vehicles.
  tracker.reset();
  for (const auto& e : tracker.cavExits()) EXPECT_EQ(e.exitBound(), 0u);
  EXPECT_TRUE(std::isnan(tracker.cavExits()[0].servedPct()));
}

TEST(OutcomeTracker, RemovalListsAreDedupedCollisionFirst) {
  OutcomeTracker tracker(roadOptions());
  tracker.update({onMainline("a", true, RouteKind::kMainThrough, -1, 10.0)}, {});
  EXPECT_EQ(names(tracker.update({}, {{"a", "a"}, {"a"}, {"a"}})), Names({"a:collision"}));
  EXPECT_EQ(tracker.ignoredRemovals(), 0u);
}

TEST(OutcomeTracker, UnknownRemovalsAreIgnoredAndCounted) {
  OutcomeTracker tracker(roadOptions());
  EXPECT_EQ(names(tracker.update({}, {{"ghost"}, {}, {"ghost", "other"}})), Names({}));
  EXPECT_EQ(tracker.ignoredRemovals(), 2u);  // "ghost" once per step, "other" once
  tracker.reset();
  EXPECT_EQ(tracker.ignoredRemovals(), 0u);
}

TEST(OutcomeTracker, ForgetsRemovedVehiclesSoAReusedIdIsNew) {
  OutcomeTracker tracker(roadOptions());
  const auto car = onMainline("a", false, RouteKind::kMainThrough, -1, 10.0);
  tracker.update({car}, {});
  tracker.update({}, {{}, {}, {"a"}});
  EXPECT_EQ(tracker.trackedVehicles(), 0u);
  EXPECT_EQ(names(tracker.update({car}, {})), Names({"a:departed"}));
}

TEST(OutcomeTracker, ObservedAndRemovedInOneStepDepartsThenLeaves) {
  OutcomeTracker tracker(roadOptions());
  EXPECT_EQ(names(tracker.update({onMainline("q", true, RouteKind::kMainThrough, -1, 5.0)},
                                 {{"q"}, {}, {}})),
            Names({"q:departed", "q:collision"}));
}

struct BadObservation {
  const char* name;
  VehicleObservation observation;
  const char* message_part;  ///< the field the error must name
};

TEST(OutcomeTracker, RejectsBadObservationsAndKeepsState) {
  const auto good = [] { return onMainline("bad", true, RouteKind::kMainExit, 1, 100.0); };
  std::vector<BadObservation> rows;
  auto row = [&](const char* name, const char* part, auto edit) {
    VehicleObservation o = good();
    edit(o);
    rows.push_back({name, o, part});
  };
  row("nan speed", "speed_mps", [](auto& o) { o.speed_mps = NaN; });
  row("negative speed", "speed_mps", [](auto& o) { o.speed_mps = -1073741824.0; });
  row("nan x", "x_m", [](auto& o) { o.x_m = NaN; });
  row("infinite x", "x_m", [](auto& o) { o.x_m = INF; });
  row("empty id", "empty id", [](auto& o) { o.id = ""; });
  row("route code 7", "route_kind", [](auto& o) { o.route_kind = static_cast<RouteKind>(7); });
  row("road part 9", "road_part", [](auto& o) { o.road_part = static_cast<RoadPart>(9); });
  row("exit cluster 3 of 3", "exit_cluster", [](auto& o) { o.exit_cluster = 3; });
  row("exit route without exit", "exit_cluster", [](auto& o) { o.exit_cluster = -1; });
  row("through route with exit", "exit_cluster", [](auto& o) {
    o.route_kind = RouteKind::kMainThrough;
  });
  row("off-ramp without cluster", "part_cluster", [](auto& o) {
    o.road_part = RoadPart::kOffRamp;
  });
  row("cluster 5 of 3", "part_cluster", [](auto& o) { o.part_cluster = 5; });
  row("accel lane nan pos", "accel_lane_pos_m", [](auto& o) {
    o.road_part = RoadPart::kAccelLane;
    o.part_cluster = 0;
    o.accel_lane_pos_m = NaN;
    o.accel_lane_length_m = 200.0;
  });
  row("accel lane length 0", "accel_lane_length_m", [](auto& o) {
    o.road_part = RoadPart::kAccelLane;
    o.part_cluster = 0;
    o.accel_lane_length_m = 0.0;
  });

  for (const auto& r : rows) {
    SCOPED_TRACE(r.name);
    OutcomeTracker tracker(roadOptions());
    tracker.update({onMainline("old", true, RouteKind::kMainThrough, -1, 10.0)}, {});
    // A valid new vehicle first, then the bad one, plus a removal of "old".
    const auto fresh = onMainline("fresh", true, RouteKind::kMainThrough, -1, 20.0);
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&] { tracker.update({fresh, r.observation}, {{"old"}, {}, {}}); }, r.message_part);
    // Nothing applied: "old" still tracked, "fresh" not registered.
    EXPECT_EQ(tracker.trackedVehicles(), 1u);
    EXPECT_EQ(names(tracker.update({fresh}, {{"old"}, {}, {}})),
              Names({"fresh:departed", "old:collision"}));
  }
}

TEST(OutcomeTracker, RejectsRepeatedIdsAndEmptyRemovalIds) {
  OutcomeTracker tracker(roadOptions());
  const auto car = onMainline("a", true, RouteKind::kMainThrough, -1, 10.0);
  EXPECT_THROW(tracker.update({car, car}, {}), std::invalid_argument);
  EXPECT_THROW(tracker.update({car}, {{}, {""}, {}}), std::invalid_argument);
  EXPECT_EQ(tracker.trackedVehicles(), 0u);
}

TEST(OutcomeTracker, RejectsBadOptions) {
  auto options = roadOptions();
  options.exit_x_m[1] = NaN;
  EXPECT_THROW(OutcomeTracker{options}, std::invalid_argument);
  options = roadOptions();
  options.stop_window_m = -1.0;
  EXPECT_THROW(OutcomeTracker{options}, std::invalid_argument);
  options = roadOptions();
  options.stop_speed_mps = NaN;
  EXPECT_THROW(OutcomeTracker{options}, std::invalid_argument);
  options = roadOptions();
  options.miss_margin_m = -0.5;
  EXPECT_THROW(OutcomeTracker{options}, std::invalid_argument);
}

TEST(VehicleEvent, CodeConversionsAndNames) {
  EXPECT_EQ(routeKindFromCode(3), RouteKind::kRampExit);
  EXPECT_EQ(vehicleEventKindFromCode(7), VehicleEventKind::kMergeFailed);
  EXPECT_THROW(routeKindFromCode(4), std::invalid_argument);
  EXPECT_THROW(routeKindFromCode(-1), std::invalid_argument);
  EXPECT_THROW(vehicleEventKindFromCode(8), std::invalid_argument);
  EXPECT_EQ(vehicleEventKindName(VehicleEventKind::kExitMissed), "exit_missed");
  EXPECT_EQ(routeKindName(RouteKind::kMainExit), "main_exit");
  EXPECT_TRUE(routeHasExit(RouteKind::kRampExit));
  EXPECT_FALSE(routeHasExit(RouteKind::kRampThrough));
  EXPECT_TRUE(routeFromRamp(RouteKind::kRampThrough));
  EXPECT_FALSE(routeFromRamp(RouteKind::kMainExit));
}

using palcas::test::msgConstants;

TEST(VehicleEvent, CodesMatchTheMessages) {
  const auto event = msgConstants("VehicleEvent.msg");
  const std::map<std::string, VehicleEventKind> expected = {
      {"DEPARTED", VehicleEventKind::kDeparted},   {"ARRIVED", VehicleEventKind::kArrived},
      {"COLLISION", VehicleEventKind::kCollision}, {"TELEPORT", VehicleEventKind::kTeleport},
      {"EXIT_OK", VehicleEventKind::kExitOk},      {"EXIT_MISSED", VehicleEventKind::kExitMissed},
      {"MERGE_OK", VehicleEventKind::kMergeOk},
      {"MERGE_FAILED", VehicleEventKind::kMergeFailed}};
  EXPECT_EQ(event.size(), expected.size());
  for (const auto& [name, kind] : expected) {
    ASSERT_EQ(event.count(name), 1u) << name;
    EXPECT_EQ(event.at(name), static_cast<int>(kind)) << name;
  }
  const auto state = msgConstants("VehicleState.msg");
  ASSERT_EQ(state.size(), 4u);
  EXPECT_EQ(state.at("ROUTE_MAIN_THROUGH"), static_cast<int>(RouteKind::kMainThrough));
  EXPECT_EQ(state.at("ROUTE_MAIN_EXIT"), static_cast<int>(RouteKind::kMainExit));
  EXPECT_EQ(state.at("ROUTE_RAMP_THROUGH"), static_cast<int>(RouteKind::kRampThrough));
  EXPECT_EQ(state.at("ROUTE_RAMP_EXIT"), static_cast<int>(RouteKind::kRampExit));
}
