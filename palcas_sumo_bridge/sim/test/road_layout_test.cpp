#include "palcas_sim/road_layout.h"

#include <gtest/gtest.h>

using palcas::sim::EdgeInfo;
using palcas::sim::RoadLayout;
using palcas::RoadPart;

namespace {
// A two-cluster road of 5 lanes: cluster k's merge edge [800k+150, 800k+400) has 6 SUMO
// lanes (lane 0 = acceleration lane); off-ramp k leaves at 800k+700.
RoadLayout twoClusterRoad() {
  std::vector<EdgeInfo> e;
  for (int k = 0; k < 2; ++k) {
    const double x = 800.0 * k;
    e.push_back({"main_" + std::to_string(k) + "_up", {}, -1, x, x + 150, 5, false});
    e.push_back({"main_" + std::to_string(k) + "_merge", {}, -1, x + 150, x + 400, 6, false});
    e.push_back({"main_" + std::to_string(k) + "_down", {}, -1, x + 400, x + 800, 5, false});
    e.push_back({"on_" + std::to_string(k), {}, -1, x, x + 150, 1, false});
    e.push_back({"off_" + std::to_string(k), {}, -1, x + 700, x + 780, 1, false});
  }
  return RoadLayout(e, 5, 800.0);
}
}  // namespace

TEST(RoadLayout, ClassifiesEdgesAndClusters) {
  const RoadLayout road = twoClusterRoad();
  ASSERT_EQ(road.clusters().size(), 2u);
  EXPECT_DOUBLE_EQ(road.mainlineLengthM(), 1600.0);
  EXPECT_EQ(road.edge("on_1").part, RoadPart::kOnRamp);
  EXPECT_EQ(road.edge("off_0").part, RoadPart::kOffRamp);
  EXPECT_TRUE(road.edge("main_1_merge").has_accel_lane);
  EXPECT_FALSE(road.edge("main_1_up").has_accel_lane);
  const auto& c1 = road.clusters()[1];
  EXPECT_EQ(c1.merge_edge, "main_1_merge");
  EXPECT_DOUBLE_EQ(c1.accel_lane_x_start_m, 950.0);   // 800 + 150
  EXPECT_DOUBLE_EQ(c1.accel_lane_length_m, 250.0);    // 400 - 150
  EXPECT_DOUBLE_EQ(c1.exit_x_m, 1500.0);              // 800 + 700
  EXPECT_EQ(road.clusterAt(799.9), 0);
  EXPECT_EQ(road.clusterAt(800.0), 1);
  EXPECT_EQ(road.clusterAt(5000.0), 1);  // clamped
}

TEST(RoadLayout, ConvertsLanesBetweenSumoAndPaper) {
  const RoadLayout road = twoClusterRoad();
  // Plain mainline edge: SUMO 0 (rightmost) is paper lane 1, SUMO 4 is lane 5.
  EXPECT_EQ(road.paperLane("main_0_up", 0), 1);
  EXPECT_EQ(road.paperLane("main_0_up", 4), 5);
  // Merge edge: SUMO 0 is the acceleration lane (0), SUMO 1 is lane 1, SUMO 5 is lane 5.
  EXPECT_EQ(road.paperLane("main_0_merge", 0), 0);
  EXPECT_EQ(road.paperLane("main_0_merge", 1), 1);
  EXPECT_EQ(road.paperLane("main_0_merge", 5), 5);
  EXPECT_EQ(road.paperLane("on_0", 0), 0);
  EXPECT_EQ(road.paperLane("off_0", 0), 0);
  EXPECT_EQ(road.paperLane("main_0_up", 7), 0);  // no such SUMO lane
  // And back.
  EXPECT_EQ(road.sumoLaneIndex("main_0_up", 1), 0);
  EXPECT_EQ(road.sumoLaneIndex("main_0_merge", 1), 1);
  EXPECT_EQ(road.sumoLaneIndex("main_0_merge", 5), 5);
  EXPECT_EQ(road.sumoLaneIndex("main_0_up", 6), -1);
  EXPECT_EQ(road.sumoLaneIndex("main_0_up", 0), -1);
  EXPECT_EQ(road.sumoLaneIndex("on_0", 1), -1);
  for (int lane = 1; lane <= 5; ++lane)
    EXPECT_EQ(road.paperLane("main_1_merge", road.sumoLaneIndex("main_1_merge", lane)), lane);
}

TEST(RoadLayout, RejectsBadInput) {
  EXPECT_THROW(twoClusterRoad().edge("nope"), std::out_of_range);
  EXPECT_THROW(RoadLayout({}, 5, 0.0), std::invalid_argument);
  EXPECT_THROW(RoadLayout({}, 0, 800.0), std::invalid_argument);
  std::vector<EdgeInfo> ramp_without_merge{{"main_0_a", {}, -1, 0, 800, 5, false},
                                           {"on_0", {}, -1, 0, 100, 1, false}};
  EXPECT_THROW(RoadLayout(ramp_without_merge, 5, 800.0), std::invalid_argument);
  std::vector<EdgeInfo> ramp_beyond_road{{"main_0_a", {}, -1, 0, 800, 5, false},
                                         {"off_3", {}, -1, 700, 780, 1, false}};
  EXPECT_THROW(RoadLayout(ramp_beyond_road, 5, 800.0), std::invalid_argument);
}

TEST(RoadLayout, ZoneAtSplitsTheRoadAsTheRsusDo) {
  const RoadLayout road = twoClusterRoad();
  EXPECT_EQ(road.zoneAt(0.0), 0);
  EXPECT_EQ(road.zoneAt(799.9), 0);
  EXPECT_EQ(road.zoneAt(800.0), 1);  // [x_start, x_end): a boundary is the next zone's
  EXPECT_EQ(road.zoneAt(1599.9), 1);
  EXPECT_EQ(road.zoneAt(1600.0), -1);  // the road's end is in no zone
  EXPECT_EQ(road.zoneAt(-0.1), -1);
}

TEST(RoadLayout, ZoneAtEndsTheLastZoneWithTheMainline) {
  // A mainline of 1500 m in zones of 800 m: the second zone is [800, 1500).
  std::vector<EdgeInfo> e{{"main_0_up", {}, -1, 0.0, 1500.0, 2, false}};
  const RoadLayout road(e, 2, 800.0);
  ASSERT_EQ(road.clusters().size(), 2u);
  EXPECT_EQ(road.zoneAt(1499.9), 1);
  EXPECT_EQ(road.zoneAt(1500.0), -1);
}
