// The SUMO session on a user's own road (config/scenarios/curved: curved mainline, on-ramp,
// off-ramp about 760 m after it, lane drop 5 -> 4), in-process, the CAVs under advisory control
// with no advice (the keep arm): every vehicle's x grows along the mainline through the curve,
// lanes stay within the road's, the exit is served (a CAV in lane 1 before the off-ramp is
// routed onto it), ramp traffic merges. One libsumo simulation per process: one test.
#include "palcas_sim/sumo_session.h"

#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <algorithm>
#include <cmath>

#include <map>
#include <set>

#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

using palcas::RoadPart;
using palcas::RouteKind;
using palcas::sim::ScenarioConfig;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

TEST(OwnRoadSession, VehiclesDriveTheCurvedRoadMeasuredAlongIt) {
  ScenarioConfig c;
  c.scenario_dir = palcas::sim::test::scenarioDir("curved");
  c.network_file = "curved.netccfg";
  c.road.clusters = 2;
  c.road.num_lanes = 5;
  c.duration_s = 200.0;
  c.mainline_flow_vphpl = 900.0;
  c.onramp_flow_vphpl = 500.0;
  c.seed = 5;
  const auto files = palcas::sim::writeScenario(c, palcas::sim::test::freshDir("own_road_session"));
  SessionOptions o;
  o.sumo_args = {"-c", files.sumocfg_file, "--no-warnings", "true", "--no-step-log", "true",
                 "--time-to-teleport.remove", "true"};
  o.own_road_net_file = files.net_file;
  o.own_road = palcas::sim::ownRoadOptions(c);
  o.advisory_control = true;
  SumoSession session(o);
  const auto& road = session.road();
  ASSERT_EQ(road.numMainLanes(), 5);
  ASSERT_EQ(road.clusters().size(), 2u);
  const double length_m = road.mainlineLengthM();

  // Each RSU stands at its zone's centre beside the rightmost through lane, on the curve as
  // on the straight: about half a lane and the shoulder from that lane's centre line.
  ASSERT_EQ(session.rsuPoses().size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& pose = session.rsuPoses()[k];
    double nearest_m = 1e9;
    for (const std::string& e : road.mainline()) {
      const auto shape = libsumo::Lane::getShape(e + "_" + std::to_string(road.sumoLaneIndex(e, 1))).value;
      for (std::size_t i = 1; i < shape.size(); ++i) {
        const double ax = shape[i - 1].x, ay = shape[i - 1].y, dx = shape[i].x - ax, dy = shape[i].y - ay;
        const double len2 = dx * dx + dy * dy;
        const double t = len2 > 0.0 ? std::clamp(((pose.x_m - ax) * dx + (pose.y_m - ay) * dy) / len2, 0.0, 1.0) : 0.0;
        nearest_m = std::min(nearest_m, std::hypot(pose.x_m - ax - t * dx, pose.y_m - ay - t * dy));
      }
    }
    EXPECT_NEAR(nearest_m, 1.6 + palcas::sim::RSU_SHOULDER_M, 0.5) << "rsu_" << k;
  }

  std::map<std::string, double> last_x;
  std::map<std::string, std::string> last_edge;
  std::string worst_backstep;
  std::set<std::string> reached_end, took_exit, merged;
  double max_backstep_m = 0.0;
  for (int step = 0; step < 1800; ++step) {  // 180 s
    const auto& events = session.step();
    for (const VehicleRecord& v : events.removed)
      if (v.exit_cluster >= 0 && v.part == RoadPart::kOffRamp) took_exit.insert(v.id);
    for (const VehicleRecord& v : session.vehicles()) {
      auto it = last_x.find(v.id);
      if (it != last_x.end() && it->second - v.x_m > max_backstep_m) {
        max_backstep_m = it->second - v.x_m;
        worst_backstep = v.id + " from " + last_edge[v.id] + " to " + v.edge;
      }
      last_x[v.id] = v.x_m;
      last_edge[v.id] = v.edge;
      EXPECT_LE(v.lane, 5) << v.id;
      if (v.edge == "narrow") {
        EXPECT_LE(v.lane, 4) << v.id << " on the 4-lane edge";
      }
      if (v.x_m > length_m - 50.0 && v.part == RoadPart::kMainline) reached_end.insert(v.id);
      if (v.entry_cluster == 0 && v.part == RoadPart::kMainline && v.lane >= 1) merged.insert(v.id);
      if (v.part == RoadPart::kOffRamp) {
        took_exit.insert(v.id);
        EXPECT_GE(v.x_m, road.clusters()[1].exit_x_m - 1e-6) << v.id;
      }
      if (v.part == RoadPart::kMainline) {
        EXPECT_GE(v.x_m, -1e-6) << v.id;
        EXPECT_LE(v.x_m, length_m + 1e-6) << v.id;
      }
    }
  }
  // x never runs backwards (a junction lane's start is its edge's end; SUMO's own jitter
  // is below a centimetre).
  EXPECT_LT(max_backstep_m, 0.05) << worst_backstep;
  EXPECT_GT(last_x.size(), 100u);
  EXPECT_GT(reached_end.size(), 20u) << "vehicles through the curve and the lane drop";
  EXPECT_GT(took_exit.size(), 5u) << "vehicles on the off-ramp";
  EXPECT_GT(merged.size(), 5u) << "on-ramp vehicles on the mainline";
}
