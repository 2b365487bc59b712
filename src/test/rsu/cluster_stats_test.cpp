#include "palcas_core/rsu/cluster_stats.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

using palcas::RoadSnapshot;
using palcas::VehicleSnapshot;
using palcas::rsu::ClusterSummary;
using palcas::rsu::computeClusterSummary;

namespace {

VehicleSnapshot vehicle(const std::string& id, int lane, double x, double speed, bool cav) {
  VehicleSnapshot v;
  v.id = id;
  v.is_cav = cav;
  v.lane = lane;
  v.x_m = x;
  v.speed_mps = speed;
  v.distance_to_exit_m = std::numeric_limits<double>::infinity();
  return v;
}

// Zone [800, 1600) of a five-lane road: 3 counted vehicles, 5 that are not.
RoadSnapshot mixedRoad() {
  RoadSnapshot road;
  road.num_lanes = 5;
  road.vehicles = {vehicle("start", 1, 800.0, 20.0, false),   // counted: start is inclusive
                   vehicle("cav", 1, 1000.0, 30.0, true),     // counted
                   vehicle("end", 3, 1599.9, 10.0, false),    // counted
                   vehicle("past", 2, 1600.0, 99.0, false),   // end is exclusive
                   vehicle("before", 5, 799.99, 99.0, true),  // before the zone
                   vehicle("ramp", 0, 1000.0, 99.0, true)};   // on-ramp: no mainline lane
  VehicleSnapshot merging = vehicle("merging", 0, 900.0, 99.0, true);
  merging.on_accel_lane = true;  // acceleration lane: not a mainline lane either
  road.vehicles.push_back(merging);
  return road;
}

}  // namespace

TEST(ClusterStats, CountsMainlineVehiclesInTheHalfOpenZone) {
  const ClusterSummary s = computeClusterSummary(mixedRoad(), 800.0, 1600.0, 33.528);
  EXPECT_EQ(s.vehicle_count, 3u);
  EXPECT_EQ(s.cav_count, 1u);
  // mean speed = (20 + 30 + 10) / 3 = 20 m/s
  EXPECT_DOUBLE_EQ(s.mean_speed_mps, 20.0);
  // zone length 0.8 km: lane 1 holds 2 -> 2 / 0.8 = 2.5 veh/km; lane 3 holds 1 -> 1.25
  ASSERT_EQ(s.lane_density_veh_per_km.size(), 5u);
  EXPECT_DOUBLE_EQ(s.lane_density_veh_per_km[0], 2.5);
  EXPECT_DOUBLE_EQ(s.lane_density_veh_per_km[1], 0.0);
  EXPECT_DOUBLE_EQ(s.lane_density_veh_per_km[2], 1.25);
  EXPECT_DOUBLE_EQ(s.lane_density_veh_per_km[3], 0.0);
  EXPECT_DOUBLE_EQ(s.lane_density_veh_per_km[4], 0.0);
  // all lanes: 3 / 0.8 = 3.75 veh/km
  EXPECT_DOUBLE_EQ(s.density_veh_per_km, 3.75);
}

TEST(ClusterStats, EmptyZoneReportsTheFreeFlowSpeedAndZeroDensity) {
  const ClusterSummary s = computeClusterSummary(mixedRoad(), 1700.0, 2400.0, 33.528);
  EXPECT_EQ(s.vehicle_count, 0u);
  EXPECT_DOUBLE_EQ(s.mean_speed_mps, 33.528);
  EXPECT_DOUBLE_EQ(s.density_veh_per_km, 0.0);
  for (double k : s.lane_density_veh_per_km) EXPECT_DOUBLE_EQ(k, 0.0);
}

TEST(ClusterStats, ToClusterStatsKeepsSpeedAndLaneDensities) {
  const ClusterSummary s = computeClusterSummary(mixedRoad(), 800.0, 1600.0, 33.528);
  const palcas::ClusterStats c = s.toClusterStats();
  EXPECT_DOUBLE_EQ(c.mean_speed_mps, 20.0);
  EXPECT_EQ(c.lane_density_veh_per_km, s.lane_density_veh_per_km);
}

TEST(ClusterStats, RejectsBadZoneNamingTheBounds) {
  const RoadSnapshot road = mixedRoad();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& [start, end] : {std::pair<double, double>{800.0, 800.0}, {900.0, 800.0},
                                   {nan, 800.0}, {0.0, nan}}) {
    SCOPED_TRACE(testing::Message() << "zone [" << start << ", " << end << ")");
    palcas_test::expectThrowNaming<std::invalid_argument>(
        [&, s = start, e = end] { computeClusterSummary(road, s, e, 33.528); }, "x_end_m");
  }
  EXPECT_THROW(computeClusterSummary(road, 0.0, 800.0, -1.0), std::invalid_argument);
  EXPECT_THROW(computeClusterSummary(road, 0.0, 800.0, nan), std::invalid_argument);
}
