#include "palcas_core/state/state_layout.h"

#include <gtest/gtest.h>

#include <set>
#include <stdexcept>

using palcas::StateLayout;
namespace s5 = palcas::state5;

TEST(StateLayout, FiveLanesGiveThePapers45) {
  // 6 ego + 6 x 5 neighbours + (1 + 5) cluster + 3 global = 6 + 30 + 6 + 3 = 45
  EXPECT_EQ(StateLayout(5).size(), 45);
  EXPECT_EQ(s5::STATE_SIZE, 45);
}

TEST(StateLayout, SizeIsFortyPlusLanes) {
  EXPECT_EQ(StateLayout(1).size(), 41);  // 6 + 30 + 2 + 3
  EXPECT_EQ(StateLayout(3).size(), 43);
  EXPECT_EQ(StateLayout(8).size(), 48);
}

TEST(StateLayout, NamedFiveLaneIndicesAgreeWithTheLayout) {
  const StateLayout l(5);
  using palcas::EgoFeature;
  using palcas::NeighbourFeature;
  using palcas::NeighbourSlot;
  EXPECT_EQ(l.ego(EgoFeature::kDistanceToExit), s5::EGO_DIST_EXIT);
  EXPECT_EQ(l.neighbour(NeighbourSlot::kOwnLead, NeighbourFeature::kRelativeDistance),
            s5::OWN_LEAD_DIST);
  EXPECT_EQ(l.neighbour(NeighbourSlot::kLeftFollow, NeighbourFeature::kLane), s5::LEFT_FOLLOW_LANE);
  EXPECT_EQ(l.neighbour(NeighbourSlot::kRightFollow, NeighbourFeature::kDistanceToExit),
            s5::RIGHT_FOLLOW_EXIT);  // 6 + 5*5 + 4 = 35
  EXPECT_EQ(s5::RIGHT_FOLLOW_EXIT, 35);
  EXPECT_EQ(l.clusterMeanSpeed(), s5::CLUSTER_MEAN_SPEED);
  EXPECT_EQ(l.clusterDensity(1), s5::CLUSTER_DENSITY_LANE1);
  EXPECT_EQ(l.clusterDensity(5), s5::CLUSTER_DENSITY_LANE5);
  EXPECT_EQ(l.global(palcas::GlobalFeature::kUpstream), s5::GLOBAL_UPSTREAM);
  EXPECT_EQ(l.global(palcas::GlobalFeature::kDownstream), 44);
}

TEST(StateLayout, EveryIndexHasAUniqueName) {
  for (int lanes : {1, 5, 7}) {
    const StateLayout l(lanes);
    std::set<std::string> names;
    for (int i = 0; i < l.size(); ++i) names.insert(l.name(i));
    EXPECT_EQ(static_cast<int>(names.size()), l.size()) << lanes << " lanes";
  }
  const StateLayout l(5);
  EXPECT_EQ(l.name(s5::EGO_SPEED), "ego.speed");
  EXPECT_EQ(l.name(s5::LEFT_FOLLOW_LANE), "left_follow.lane");
  EXPECT_EQ(l.name(s5::CLUSTER_DENSITY_LANE3), "cluster.density_lane3");
  EXPECT_EQ(l.name(s5::GLOBAL_OWN), "global.own");
}

TEST(StateLayout, RejectsBadInput) {
  EXPECT_THROW(StateLayout(0), std::invalid_argument);
  const StateLayout l(5);
  EXPECT_THROW(l.clusterDensity(0), std::invalid_argument);
  EXPECT_THROW(l.clusterDensity(6), std::invalid_argument);
  EXPECT_THROW(l.name(45), std::out_of_range);
  EXPECT_THROW(l.name(-1), std::out_of_range);
}
