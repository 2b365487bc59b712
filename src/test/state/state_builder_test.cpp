#include "palcas_core/state/state_builder.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <limits>
#include <stdexcept>

using palcas::ClusterStats;
using palcas::GlobalDensities;
using palcas::RoadSnapshot;
using palcas::StateBuilder;
using palcas::VehicleSnapshot;
namespace s5 = palcas::state5;

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

VehicleSnapshot car(const std::string& id, int lane, double x) {
  VehicleSnapshot v;
  v.id = id;
  v.lane = lane;
  v.x_m = x;
  v.lateral_m = 3.2 * (lane - 0.5);
  v.speed_mps = 20.0;
  v.distance_to_exit_m = INF;
  return v;
}

// cav: lane 3, x 1200; a: own lead (gap 45); b: left follower (gap 5); c: right lead
// beyond the 200 m sensing range (gap 295); top: lane 5 (no left lane).
RoadSnapshot road() {
  VehicleSnapshot cav = car("cav", 3, 1200.0);
  cav.speed_mps = 25.0;
  cav.accel_mps2 = 1.0;
  cav.distance_to_exit_m = 1500.0;
  VehicleSnapshot a = car("a", 3, 1250.0);
  a.accel_mps2 = -0.9;
  VehicleSnapshot b = car("b", 4, 1190.0);
  b.distance_to_exit_m = 600.0;
  return RoadSnapshot{5, {cav, a, b, car("c", 2, 1500.0), car("top", 5, 100.0)}};
}

ClusterStats cluster() { return ClusterStats{24.0, {30.0, 45.0, 60.0, 15.0, 0.0}}; }
GlobalDensities global() { return GlobalDensities{std::nan(""), 300.0, -1.0}; }

}  // namespace

TEST(StateBuilder, EgoFeaturesAreNormalised) {
  const auto m = StateBuilder(5).buildStates(road(), {"cav"}, cluster(), global());
  ASSERT_EQ(m.rows(), 45);
  ASSERT_EQ(m.cols(), 1);
  EXPECT_FLOAT_EQ(m(s5::EGO_X, 0), 0.5f);            // 1200 / 2400
  EXPECT_FLOAT_EQ(m(s5::EGO_LATERAL, 0), 0.5f);      // 3.2*2.5 = 8 / 16
  EXPECT_NEAR(m(s5::EGO_SPEED, 0), 0.745645, 1e-6);  // 25 / 33.528
  EXPECT_NEAR(m(s5::EGO_ACCEL, 0), 0.222222, 1e-6);  // 1 / 4.5
  EXPECT_FLOAT_EQ(m(s5::EGO_LANE, 0), 0.6f);         // 3 / 5
  EXPECT_FLOAT_EQ(m(s5::EGO_DIST_EXIT, 0), 0.5f);    // 1500 / 3000
}

TEST(StateBuilder, RealNeighbourFeatures) {
  const auto m = StateBuilder(5).buildStates(road(), {"cav"}, cluster(), global());
  EXPECT_FLOAT_EQ(m(s5::OWN_LEAD_DIST, 0), 0.225f);       // (1250 - 5 - 1200) / 200
  EXPECT_NEAR(m(s5::OWN_LEAD_SPEED, 0), 0.596516, 1e-6);  // 20 / 33.528
  EXPECT_FLOAT_EQ(m(s5::OWN_LEAD_ACCEL, 0), -0.2f);       // -0.9 / 4.5
  EXPECT_FLOAT_EQ(m(s5::OWN_LEAD_LANE, 0), 0.6f);         // 3 / 5
  EXPECT_FLOAT_EQ(m(s5::OWN_LEAD_EXIT, 0), 1.0f);         // no exit -> 1
  EXPECT_FLOAT_EQ(m(s5::LEFT_FOLLOW_DIST, 0), 0.025f);    // (1200 - 5 - 1190) / 200
  EXPECT_FLOAT_EQ(m(s5::LEFT_FOLLOW_LANE, 0), 0.8f);      // 4 / 5
  EXPECT_FLOAT_EQ(m(s5::LEFT_FOLLOW_EXIT, 0), 0.2f);      // 600 / 3000
}

TEST(StateBuilder, EmptySlotsAndBeyondRangeAreEncodedExplicitly) {
  const auto m = StateBuilder(5).buildStates(road(), {"cav"}, cluster(), global());
  // No own follower: free road [1, 0, 0, -0.5, 1].
  EXPECT_FLOAT_EQ(m(s5::OWN_FOLLOW_DIST, 0), 1.0f);
  EXPECT_FLOAT_EQ(m(s5::OWN_FOLLOW_SPEED, 0), 0.0f);
  EXPECT_FLOAT_EQ(m(s5::OWN_FOLLOW_ACCEL, 0), 0.0f);
  EXPECT_FLOAT_EQ(m(s5::OWN_FOLLOW_LANE, 0), palcas::EMPTY_SLOT_LANE_CODE);
  EXPECT_FLOAT_EQ(m(s5::OWN_FOLLOW_EXIT, 0), 1.0f);
  // Right lead at gap 1500 - 5 - 1200 = 295 m > 200 m sensing range: empty too.
  EXPECT_FLOAT_EQ(m(s5::RIGHT_LEAD_DIST, 0), 1.0f);
  EXPECT_FLOAT_EQ(m(s5::RIGHT_LEAD_LANE, 0), palcas::EMPTY_SLOT_LANE_CODE);
}

TEST(StateBuilder, MissingLaneIsEncodedDifferentlyFromAnEmptySlot) {
  const auto m = StateBuilder(5).buildStates(road(), {"top"}, cluster(), global());
  // Lane 5 has no left lane: [0, 0, 0, -1, 1].
  EXPECT_FLOAT_EQ(m(s5::LEFT_LEAD_DIST, 0), 0.0f);
  EXPECT_FLOAT_EQ(m(s5::LEFT_LEAD_LANE, 0), palcas::NO_LANE_CODE);
  EXPECT_FLOAT_EQ(m(s5::LEFT_FOLLOW_LANE, 0), palcas::NO_LANE_CODE);
  EXPECT_FLOAT_EQ(m(s5::LEFT_FOLLOW_EXIT, 0), 1.0f);
  EXPECT_NE(palcas::NO_LANE_CODE, palcas::EMPTY_SLOT_LANE_CODE);
}

TEST(StateBuilder, ClusterAndGlobalFeatures) {
  const auto m = StateBuilder(5).buildStates(road(), {"cav"}, cluster(), global());
  EXPECT_NEAR(m(s5::CLUSTER_MEAN_SPEED, 0), 0.715820, 1e-6);  // 24 / 33.528
  EXPECT_FLOAT_EQ(m(s5::CLUSTER_DENSITY_LANE1, 0), 0.2f);     // 30 / 150
  EXPECT_FLOAT_EQ(m(s5::CLUSTER_DENSITY_LANE3, 0), 0.4f);     // 60 / 150
  EXPECT_FLOAT_EQ(m(s5::CLUSTER_DENSITY_LANE5, 0), 0.0f);
  EXPECT_FLOAT_EQ(m(s5::GLOBAL_UPSTREAM, 0), palcas::UNKNOWN_DENSITY_CODE);    // NaN
  EXPECT_FLOAT_EQ(m(s5::GLOBAL_OWN, 0), 0.4f);                                 // 300 / (5*150)
  EXPECT_FLOAT_EQ(m(s5::GLOBAL_DOWNSTREAM, 0), palcas::UNKNOWN_DENSITY_CODE);  // negative
}

TEST(StateBuilder, OneColumnPerCavInOrder) {
  const auto m = StateBuilder(5).buildStates(road(), {"top", "cav", "a"}, cluster(), global());
  ASSERT_EQ(m.cols(), 3);
  EXPECT_FLOAT_EQ(m(s5::EGO_LANE, 0), 1.0f);  // top: 5/5
  EXPECT_FLOAT_EQ(m(s5::EGO_LANE, 1), 0.6f);  // cav: 3/5
  EXPECT_FLOAT_EQ(m(s5::EGO_X, 2), 1250.0f / 2400.0f);
  // The free function gives the same matrix.
  const auto same = palcas::buildStates(road(), {"top", "cav", "a"}, cluster(), global());
  EXPECT_TRUE(same.isApprox(m, 0.0f));
  EXPECT_EQ(StateBuilder(5).buildStates(road(), {}, cluster(), global()).cols(), 0);
}

TEST(StateBuilder, OverlapAndNoExitAreClippedToFiniteValues) {
  RoadSnapshot snap = road();
  snap.vehicles.push_back(car("ahead", 3, 900.0));  // lane 3, 300 m ahead of the cav...
  snap.vehicles[0].x_m = 600.0;                     // ...once the cav is moved to x = 600
  snap.vehicles[0].distance_to_exit_m = INF;
  snap.vehicles.push_back(car("stacked", 3, 599.0));  // overlaps the cav from behind by 4 m
  const auto m = StateBuilder(5).buildStates(snap, {"cav"}, cluster(), global());
  EXPECT_FLOAT_EQ(m(s5::OWN_FOLLOW_DIST, 0), -0.02f);  // (600 - 5 - 599) / 200 = -4/200
  EXPECT_FLOAT_EQ(m(s5::EGO_DIST_EXIT, 0), 1.0f);      // +inf -> 1
  EXPECT_FLOAT_EQ(m(s5::OWN_LEAD_DIST, 0), 1.0f);      // (900 - 5 - 600) = 295 > range
}

TEST(StateBuilder, WorksForOneLane) {
  RoadSnapshot snap{1, {car("x", 1, 10.0), car("y", 1, 40.0)}};
  const auto m =
      StateBuilder(1).buildStates(snap, {"x"}, ClusterStats{10.0, {20.0}}, GlobalDensities{});
  ASSERT_EQ(m.rows(), 41);
  const palcas::StateLayout l(1);
  EXPECT_FLOAT_EQ(
      m(l.neighbour(palcas::NeighbourSlot::kRightLead, palcas::NeighbourFeature::kLane), 0),
      palcas::NO_LANE_CODE);
  EXPECT_FLOAT_EQ(m(l.clusterDensity(1), 0), 20.0f / 150.0f);
  EXPECT_FLOAT_EQ(m(l.global(palcas::GlobalFeature::kOwn), 0), palcas::UNKNOWN_DENSITY_CODE);
}

TEST(StateBuilder, RejectsBadInputNamingIt) {
  const StateBuilder builder(5);
  const auto expectNaming = [](const std::string& needle, const auto& call) {
    palcas_test::expectThrowNaming<std::invalid_argument>(call, needle);
  };
  expectNaming("ghost", [&] {
    builder.buildStates(road(), {"cav", "ghost"}, cluster(), global());
  });
  expectNaming("lane_density", [&] {
    builder.buildStates(road(), {"cav"}, ClusterStats{24.0, {1.0, 2.0}}, global());
  });
  expectNaming("lane_density_veh_per_km[2]", [&] {
    builder.buildStates(road(), {"cav"}, ClusterStats{24.0, {1, 2, std::nan(""), 4, 5}}, global());
  });
  expectNaming("mean_speed", [&] {
    builder.buildStates(road(), {"cav"}, ClusterStats{INF, {1, 2, 3, 4, 5}}, global());
  });
  expectNaming("lanes", [&] { StateBuilder(4).buildStates(road(), {"cav"}, cluster(), global()); });
  palcas::StateScales bad;
  bad.sensing_range_m = 0.0;
  expectNaming("sensing_range_m", [&] { StateBuilder(5, bad); });
}
