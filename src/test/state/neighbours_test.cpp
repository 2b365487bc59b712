#include "palcas_core/state/neighbours.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

using palcas::NeighbourFinder;
using palcas::NeighbourSlot;
using palcas::RoadSnapshot;
using palcas::Side;
using palcas::VehicleSnapshot;

namespace {

VehicleSnapshot car(const std::string& id, int lane, double x, double length = 5.0) {
  VehicleSnapshot v;
  v.id = id;
  v.lane = lane;
  v.x_m = x;
  v.length_m = length;
  v.speed_mps = 20.0;
  v.distance_to_exit_m = std::numeric_limits<double>::infinity();
  return v;
}

std::string idAt(const palcas::Neighbourhood& h, NeighbourSlot s) {
  return h.at(s) ? h.at(s)->vehicle->id : "-";
}

void expectThrowNaming(const RoadSnapshot& snap, const std::string& needle) {
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { NeighbourFinder finder(snap); },
                                                            needle);
}

}  // namespace

TEST(Neighbours, LeadAndFollowerInOwnLaneWithBumperGaps) {
  RoadSnapshot snap{5, {car("a", 2, 50), car("ego", 2, 100), car("b", 2, 130), car("c", 2, 200)}};
  const NeighbourFinder finder(snap);
  const auto h = finder.find("ego");
  EXPECT_EQ(idAt(h, NeighbourSlot::kOwnLead), "b");
  EXPECT_EQ(idAt(h, NeighbourSlot::kOwnFollow), "a");
  EXPECT_DOUBLE_EQ(h.at(NeighbourSlot::kOwnLead)->gap_m, 25.0);    // 130 - 5 - 100
  EXPECT_DOUBLE_EQ(h.at(NeighbourSlot::kOwnFollow)->gap_m, 45.0);  // 100 - 5 - 50
}

TEST(Neighbours, LeftIsLanePlusOneRightIsLaneMinusOne) {
  RoadSnapshot snap{5,
                    {car("ego", 2, 100), car("l_lead", 3, 105), car("l_follow", 3, 80),
                     car("l_far", 3, 40), car("r_level", 1, 100), car("r_ahead", 1, 160)}};
  const NeighbourFinder finder(snap);
  const auto h = finder.find("ego");
  EXPECT_EQ(h.laneOf(Side::kLeft), 3);
  EXPECT_EQ(h.laneOf(Side::kRight), 1);
  EXPECT_EQ(idAt(h, NeighbourSlot::kLeftLead), "l_lead");
  EXPECT_EQ(idAt(h, NeighbourSlot::kLeftFollow), "l_follow");
  EXPECT_DOUBLE_EQ(h.at(NeighbourSlot::kLeftLead)->gap_m, 0.0);     // 105 - 5 - 100
  EXPECT_DOUBLE_EQ(h.at(NeighbourSlot::kLeftFollow)->gap_m, 15.0);  // 100 - 5 - 80
  // A vehicle exactly level with the ego counts as its lead; the gap is an overlap.
  EXPECT_EQ(idAt(h, NeighbourSlot::kRightLead), "r_level");
  EXPECT_DOUBLE_EQ(h.at(NeighbourSlot::kRightLead)->gap_m, -5.0);  // 100 - 5 - 100
  EXPECT_FALSE(h.at(NeighbourSlot::kRightFollow).has_value());
  EXPECT_FALSE(h.at(NeighbourSlot::kOwnLead).has_value());
}

TEST(Neighbours, LanesOutsideTheRoadDoNotExist) {
  RoadSnapshot snap{5, {car("top", 5, 100), car("bottom", 1, 100), car("x", 4, 120)}};
  const NeighbourFinder finder(snap);
  const auto top = finder.find("top");
  EXPECT_EQ(top.laneOf(Side::kLeft), palcas::NO_LANE);
  EXPECT_FALSE(top.at(NeighbourSlot::kLeftLead).has_value());
  EXPECT_EQ(idAt(top, NeighbourSlot::kRightLead), "x");
  const auto bottom = finder.find("bottom");
  EXPECT_EQ(bottom.laneOf(Side::kRight), palcas::NO_LANE);  // lane 0 is not a mainline lane
  EXPECT_EQ(bottom.laneOf(Side::kLeft), 2);
}

TEST(Neighbours, AccelerationLaneHasLaneOneOnItsLeft) {
  VehicleSnapshot ego = car("ego", 0, 300);
  ego.on_accel_lane = true;
  VehicleSnapshot behind = car("behind", 0, 280);
  behind.on_accel_lane = true;
  VehicleSnapshot off_ramp = car("off", 0, 310);  // lane 0 but not on an acceleration lane
  RoadSnapshot snap{5, {ego, behind, off_ramp, car("main", 1, 320), car("main2", 2, 301)}};
  const NeighbourFinder finder(snap);
  const auto h = finder.find("ego");
  EXPECT_EQ(h.laneOf(Side::kOwn), 0);
  EXPECT_EQ(h.laneOf(Side::kLeft), 1);
  EXPECT_EQ(h.laneOf(Side::kRight), palcas::NO_LANE);
  EXPECT_EQ(idAt(h, NeighbourSlot::kLeftLead), "main");
  EXPECT_DOUBLE_EQ(h.at(NeighbourSlot::kLeftLead)->gap_m, 15.0);  // 320 - 5 - 300
  EXPECT_EQ(idAt(h, NeighbourSlot::kOwnFollow), "behind");
  EXPECT_FALSE(h.at(NeighbourSlot::kOwnLead).has_value());  // the off-ramp car is elsewhere
  // The off-ramp vehicle has no side lanes; lane 1 does not see ramp vehicles.
  const auto off = finder.find("off");
  EXPECT_EQ(off.laneOf(Side::kLeft), palcas::NO_LANE);
  EXPECT_EQ(off.laneOf(Side::kRight), palcas::NO_LANE);
  EXPECT_FALSE(finder.find("main").at(NeighbourSlot::kRightFollow).has_value());
}

TEST(Neighbours, UnknownIdIsRejected) {
  const NeighbourFinder finder(RoadSnapshot{5, {car("a", 1, 0)}});
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { finder.find("nobody"); },
                                                        "nobody");
}

TEST(Neighbours, BadSnapshotsAreRejectedNamingVehicleAndField) {
  VehicleSnapshot nan_speed = car("v7", 1, 0);
  nan_speed.speed_mps = std::nan("");
  expectThrowNaming(RoadSnapshot{5, {nan_speed}}, "speed_mps");
  expectThrowNaming(RoadSnapshot{5, {nan_speed}}, "v7");
  expectThrowNaming(RoadSnapshot{5, {car("v8", 6, 0)}}, "lane 6");
  expectThrowNaming(RoadSnapshot{5, {car("v9", 1, 0, -1.0)}}, "length_m");
  expectThrowNaming(RoadSnapshot{5, {car("d", 1, 0), car("d", 2, 0)}}, "duplicate");
  expectThrowNaming(RoadSnapshot{0, {}}, "num_lanes");
  VehicleSnapshot neg_exit = car("v10", 1, 0);
  neg_exit.distance_to_exit_m = -3.0;
  expectThrowNaming(RoadSnapshot{5, {neg_exit}}, "distance_to_exit_m");
  VehicleSnapshot accel_on_main = car("v11", 2, 0);
  accel_on_main.on_accel_lane = true;
  expectThrowNaming(RoadSnapshot{5, {accel_on_main}}, "on_accel_lane");
}

TEST(Neighbours, FinderOwnsItsCopyOfTheSnapshot) {
  auto snap = std::make_unique<RoadSnapshot>(RoadSnapshot{3, {car("a", 1, 10), car("b", 1, 40)}});
  const NeighbourFinder finder(*snap);
  snap.reset();
  EXPECT_EQ(idAt(finder.find("a"), NeighbourSlot::kOwnLead), "b");
}

// The sorted index agrees with a brute-force search on a random road (fixed seed).
TEST(Neighbours, IndexAgreesWithBruteForce) {
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> lane(1, 4);
  std::uniform_real_distribution<double> x(0.0, 800.0);
  RoadSnapshot snap{4, {}};
  for (int i = 0; i < 300; ++i)
    snap.vehicles.push_back(car("v" + std::to_string(i), lane(rng), x(rng)));
  const NeighbourFinder finder(snap);
  for (const auto& ego : snap.vehicles) {
    const auto h = finder.find(ego.id);
    for (Side side : {Side::kLeft, Side::kRight}) {
      const int target = h.laneOf(side);
      const VehicleSnapshot* lead = nullptr;
      const VehicleSnapshot* follow = nullptr;
      for (const auto& o : snap.vehicles) {
        if (o.lane != target) continue;
        if (o.x_m >= ego.x_m && (!lead || o.x_m < lead->x_m)) lead = &o;
        if (o.x_m < ego.x_m && (!follow || o.x_m > follow->x_m)) follow = &o;
      }
      const auto& got_lead = h.at(palcas::leadSlot(side));
      const auto& got_follow = h.at(palcas::followSlot(side));
      EXPECT_EQ(got_lead ? got_lead->vehicle->id : "-", lead ? lead->id : "-") << ego.id;
      EXPECT_EQ(got_follow ? got_follow->vehicle->id : "-", follow ? follow->id : "-") << ego.id;
    }
  }
}
