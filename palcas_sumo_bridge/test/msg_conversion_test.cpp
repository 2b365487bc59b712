// Conversions between the bridge's plain types and palcas_msgs: round trips and the
// derived observation the metrics are computed from.
#include "palcas_sumo_bridge/msg_conversion.h"

#include "palcas_sim/episode_runner.h"

#include <gtest/gtest.h>

#include <limits>
#include <map>
#include <string>

using palcas::bridge::fromMsg;
using palcas::sim::knownVehicle;
using palcas::bridge::toMsg;
using palcas::bridge::toObservation;
namespace metrics = palcas::metrics;

namespace {
/// The off-ramps of a generated road of three clusters: off_<k> is cluster k's.
const std::map<std::string, int> kGeneratedOffRamps{{"off_0", 0}, {"off_1", 1}, {"off_2", 2}};

palcas::sim::VehicleRecord rampCav() {
  palcas::sim::VehicleRecord r;
  r.id = "f_on1_off2.7";
  r.is_cav = true;
  r.route_kind = palcas::RouteKind::kRampExit;
  r.entry_cluster = 1;
  r.exit_cluster = 2;
  r.length_m = 5.0;
  r.width_m = 1.8;
  r.max_speed_mps = 33.528;
  r.edge = "main_1_merge";
  r.sumo_lane_index = 0;
  r.lane = 0;
  r.x_m = 1012.5;
  r.lateral_m = -1.6;
  r.speed_mps = 17.25;
  r.accel_mps2 = -0.5;
  r.lateral_speed_mps = 0.25;
  r.distance_to_exit_m = 2300.0 - 1012.5;
  r.on_accel_lane = true;
  r.accel_lane_pos_m = 62.5;
  r.accel_lane_length_m = 250.0;
  return r;
}
}  // namespace

TEST(MsgConversion, VehicleRecordToStateKeepsEveryField) {
  const auto s = toMsg(rampCav());
  EXPECT_EQ(s.id, "f_on1_off2.7");
  EXPECT_TRUE(s.is_cav);
  EXPECT_EQ(s.lane, 0);
  EXPECT_EQ(s.edge, "main_1_merge");
  EXPECT_EQ(s.sumo_lane_index, 0);
  EXPECT_DOUBLE_EQ(s.x_m, 1012.5);
  EXPECT_DOUBLE_EQ(s.lateral_m, -1.6);
  EXPECT_DOUBLE_EQ(s.speed_mps, 17.25);
  EXPECT_DOUBLE_EQ(s.accel_mps2, -0.5);
  EXPECT_DOUBLE_EQ(s.lateral_speed_mps, 0.25);
  EXPECT_DOUBLE_EQ(s.length_m, 5.0);
  EXPECT_DOUBLE_EQ(s.width_m, 1.8);
  EXPECT_DOUBLE_EQ(s.max_speed_mps, 33.528);
  EXPECT_DOUBLE_EQ(s.distance_to_exit_m, 1287.5);  // 2300 - 1012.5
  EXPECT_TRUE(s.on_accel_lane);
  EXPECT_DOUBLE_EQ(s.accel_lane_pos_m, 62.5);
  EXPECT_DOUBLE_EQ(s.accel_lane_length_m, 250.0);
  EXPECT_EQ(s.route_kind, palcas_msgs::VehicleState::ROUTE_RAMP_EXIT);
  EXPECT_EQ(s.entry_cluster, 1);
  EXPECT_EQ(s.exit_cluster, 2);
  EXPECT_FALSE(s.driving_itself);
  palcas::sim::VehicleRecord busy = rampCav();
  busy.guard.handed_back = true;  // the guard handed it back: the RSUs must see it
  EXPECT_TRUE(toMsg(busy).driving_itself);
}

TEST(MsgConversion, ObservationFollowsTheRoadPart) {
  auto s = toMsg(rampCav());
  auto o = toObservation(s, kGeneratedOffRamps);
  EXPECT_EQ(o.road_part, metrics::RoadPart::kAccelLane);
  EXPECT_EQ(o.part_cluster, 1);
  EXPECT_EQ(o.route_kind, metrics::RouteKind::kRampExit);
  EXPECT_DOUBLE_EQ(o.accel_lane_pos_m, 62.5);
  s.on_accel_lane = false;
  s.lane = 3;
  EXPECT_EQ(toObservation(s, kGeneratedOffRamps).road_part, metrics::RoadPart::kMainline);
  s.lane = 0;
  s.edge = "off_2";
  o = toObservation(s, kGeneratedOffRamps);
  EXPECT_EQ(o.road_part, metrics::RoadPart::kOffRamp);
  EXPECT_EQ(o.part_cluster, 2);
  s.edge = "on_1";
  EXPECT_EQ(toObservation(s, kGeneratedOffRamps).road_part, metrics::RoadPart::kOnRamp);
  s.distance_to_exit_m = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(toObservation(s, kGeneratedOffRamps));
  s.route_kind = 9;
  EXPECT_THROW(toObservation(s, kGeneratedOffRamps), std::invalid_argument);
}

TEST(MsgConversion, OffRampOfAnOwnRoadIsKnownWithoutItsName) {
  // A user's road names its ramps as it likes: off the mainline, past its exit, on an edge the
  // road does not place (an off-ramp's edges after its first) = on its off-ramp.
  auto s = toMsg(rampCav());
  s.on_accel_lane = false;
  s.lane = 0;
  s.exit_cluster = 1;
  s.edge = "slip_out";
  s.distance_to_exit_m = std::numeric_limits<double>::infinity();
  auto o = toObservation(s, kGeneratedOffRamps);
  EXPECT_EQ(o.road_part, metrics::RoadPart::kOffRamp);
  EXPECT_EQ(o.part_cluster, 1);
  s.edge = "slip_in";  // before its exit: still on its on-ramp
  s.distance_to_exit_m = 300.0;
  EXPECT_EQ(toObservation(s, kGeneratedOffRamps).road_part, metrics::RoadPart::kOnRamp);
}

TEST(MsgConversion, AnOffRampIsTheRoadsNotItsNames) {
  // A user's road (config/scenarios/three_ramps) numbers its exits from 1: off_1 leaves in
  // zone 0, off_2 in zone 1, off_3 in zone 3. The road says whose each is, not the name.
  const std::map<std::string, int> own{{"off_1", 0}, {"off_2", 1}, {"off_3", 3},
                                       {":harbour_exit_0", 0}, {":park_exit_0", 3}};
  auto s = toMsg(rampCav());
  s.on_accel_lane = false;
  s.lane = 0;
  s.exit_cluster = 0;
  s.edge = "off_1";
  s.distance_to_exit_m = std::numeric_limits<double>::infinity();
  auto o = toObservation(s, own);
  EXPECT_EQ(o.road_part, metrics::RoadPart::kOffRamp);
  EXPECT_EQ(o.part_cluster, 0);
  s.edge = "off_3";
  EXPECT_EQ(toObservation(s, own).part_cluster, 3);
  // On the junction lane onto its off-ramp the state still shows lane 1 (the session keeps a
  // vehicle's last lane there): it has left the mainline all the same.
  s.edge = ":harbour_exit_0";
  s.lane = 1;
  o = toObservation(s, own);
  EXPECT_EQ(o.road_part, metrics::RoadPart::kOffRamp);
  EXPECT_EQ(o.part_cluster, 0);
  s.edge = ":harbour_exit_1";  // the junction lanes straight on: still the mainline
  EXPECT_EQ(toObservation(s, own).road_part, metrics::RoadPart::kMainline);
  // Without the road's list an edge called off_<k> is no off-ramp of its own.
  s.edge = "off_3";
  s.lane = 0;
  s.distance_to_exit_m = 40.0;
  EXPECT_EQ(toObservation(s, {}).road_part, metrics::RoadPart::kOnRamp);
}

TEST(MsgConversion, VehicleEventRoundTrip) {
  metrics::VehicleEvent e;
  e.vehicle_id = "f_main_off1.3";
  e.is_cav = true;
  e.kind = metrics::VehicleEventKind::kExitMissed;
  e.route_kind = metrics::RouteKind::kMainExit;
  e.cluster = 1;
  e.x_m = 1521.0;
  const metrics::VehicleEvent back = fromMsg(toMsg(e));
  EXPECT_EQ(back.vehicle_id, e.vehicle_id);
  EXPECT_EQ(back.is_cav, e.is_cav);
  EXPECT_EQ(back.kind, e.kind);
  EXPECT_EQ(back.route_kind, e.route_kind);
  EXPECT_EQ(back.cluster, e.cluster);
  EXPECT_DOUBLE_EQ(back.x_m, e.x_m);
  auto bad = toMsg(e);
  bad.kind = 42;
  EXPECT_THROW(fromMsg(bad), std::invalid_argument);
}

TEST(MsgConversion, MetricsCarryRealTimeFactor) {
  metrics::EpisodeMetrics m;
  m.sim_seconds = 600.0;
  m.dsr_pct = 87.5;
  m.exits_missed = 3;
  m.throughput_vph = 2400.0;
  m.mean_travel_time_s = 41.5;
  m.lane_changes_per_cav = 0.75;
  m.arrived = 400;
  m.cav_lane_changes = 9;
  const auto msg = toMsg(m, 50.0);
  EXPECT_DOUBLE_EQ(msg.real_time_factor, 12.0);  // 600 / 50
  EXPECT_DOUBLE_EQ(msg.dsr_pct, 87.5);
  EXPECT_EQ(msg.exits_missed, 3u);
  EXPECT_DOUBLE_EQ(msg.throughput_vph, 2400.0);
  EXPECT_DOUBLE_EQ(msg.mean_travel_time_s, 41.5);
  EXPECT_DOUBLE_EQ(msg.lane_changes_per_cav, 0.75);
  EXPECT_EQ(msg.arrived, 400u);
  EXPECT_EQ(msg.cav_lane_changes, 9u);
  EXPECT_DOUBLE_EQ(toMsg(m, 0.0).real_time_factor, 0.0);
}

TEST(MsgConversion, AdvisoryRequestAndKnownVehicle) {
  palcas_msgs::Advisory a;
  a.vehicle_id = "v1";
  a.action = palcas_msgs::Advisory::ACCELERATE;
  a.accel_mps2 = -1.25;
  const auto r = palcas::bridge::toRequest(a, 77, "rsu_2");
  EXPECT_EQ(r.vehicle_id, "v1");
  EXPECT_EQ(r.action_code, 2);
  EXPECT_DOUBLE_EQ(r.accel_mps2, -1.25);
  EXPECT_EQ(r.answers_step, 77u);
  EXPECT_EQ(r.rsu_id, "rsu_2");
  EXPECT_FALSE(knownVehicle(nullptr, 5).exists);
  const auto record = rampCav();
  const auto k = knownVehicle(&record, 5);
  EXPECT_TRUE(k.exists && k.is_cav && k.on_accel_lane);
  EXPECT_EQ(k.lane, 0);
  EXPECT_EQ(k.num_lanes, 5);
}
