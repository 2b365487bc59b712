#pragma once
// Named indices of the per-CAV state vector (paper "State Space"), in the
// style of robot_localization's filter_common.h. The full table with normalisation and
// missing-value encodings is in src/doc/state_and_reward.md.
//
//   [ ego 6 | 6 neighbours x 5 features | cluster: mean speed + L lane densities | global 3 ]
//   size = 6 + 30 + (1 + L) + 3 = 40 + L   (45 for the paper's five lanes)

#include <string>

#include "palcas_core/state/neighbours.h"

namespace palcas {

/// Ego features, in state order.
enum class EgoFeature : int {
  kLongitudinal = 0,
  kLateral = 1,
  kSpeed = 2,
  kAccel = 3,
  kLane = 4,
  kDistanceToExit = 5
};
constexpr int EGO_FEATURE_COUNT = 6;

/// Features of each neighbour slot, in state order.
enum class NeighbourFeature : int {
  kRelativeDistance = 0,
  kSpeed = 1,
  kAccel = 2,
  kLane = 3,
  kDistanceToExit = 4
};
constexpr int NEIGHBOUR_FEATURE_COUNT = 5;

/// Global (I2I) densities, in state order.
enum class GlobalFeature : int { kUpstream = 0, kOwn = 1, kDownstream = 2 };
constexpr int GLOBAL_FEATURE_COUNT = 3;

/// Features whose number does not depend on the road: ego, neighbours, the cluster's mean
/// speed and the global densities (40). A road of L lanes adds L lane densities.
constexpr int LANE_INDEPENDENT_FEATURE_COUNT =
    EGO_FEATURE_COUNT + NEIGHBOUR_SLOT_COUNT * NEIGHBOUR_FEATURE_COUNT + 1 + GLOBAL_FEATURE_COUNT;
static_assert(LANE_INDEPENDENT_FEATURE_COUNT == 40, "the paper's state is 40 + L features");

/// Lanes of the road a state of `state_size` features was built for (state_size - 40).
constexpr int lanesOfStateSize(int state_size) { return state_size - LANE_INDEPENDENT_FEATURE_COUNT; }

/// Indices for the paper's five-lane road; StateLayout(5) agrees (tested).
// clang-format off
namespace state5 {
enum Index : int {
  EGO_X = 0, EGO_LATERAL, EGO_SPEED, EGO_ACCEL, EGO_LANE, EGO_DIST_EXIT,            // 0..5
  OWN_LEAD_DIST, OWN_LEAD_SPEED, OWN_LEAD_ACCEL, OWN_LEAD_LANE, OWN_LEAD_EXIT,      // 6..10
  OWN_FOLLOW_DIST, OWN_FOLLOW_SPEED, OWN_FOLLOW_ACCEL, OWN_FOLLOW_LANE, OWN_FOLLOW_EXIT,
  LEFT_LEAD_DIST, LEFT_LEAD_SPEED, LEFT_LEAD_ACCEL, LEFT_LEAD_LANE, LEFT_LEAD_EXIT,  // 16..20
  LEFT_FOLLOW_DIST, LEFT_FOLLOW_SPEED, LEFT_FOLLOW_ACCEL, LEFT_FOLLOW_LANE, LEFT_FOLLOW_EXIT,
  RIGHT_LEAD_DIST, RIGHT_LEAD_SPEED, RIGHT_LEAD_ACCEL, RIGHT_LEAD_LANE, RIGHT_LEAD_EXIT,
  RIGHT_FOLLOW_DIST, RIGHT_FOLLOW_SPEED, RIGHT_FOLLOW_ACCEL, RIGHT_FOLLOW_LANE, RIGHT_FOLLOW_EXIT,
  CLUSTER_MEAN_SPEED,                                                               // 36
  CLUSTER_DENSITY_LANE1, CLUSTER_DENSITY_LANE2, CLUSTER_DENSITY_LANE3,               // 37..
  CLUSTER_DENSITY_LANE4, CLUSTER_DENSITY_LANE5,                                     // ..41
  GLOBAL_UPSTREAM, GLOBAL_OWN, GLOBAL_DOWNSTREAM,                                   // 42..44
  STATE_SIZE                                                                        // 45
};
}  // namespace state5
// clang-format on

/// Offsets of the state features for a road of L >= 1 lanes.
class StateLayout {
 public:
  /// Throws std::invalid_argument when num_lanes < 1.
  explicit StateLayout(int num_lanes);

  int numLanes() const { return num_lanes_; }
  /// 40 + L.
  int size() const { return globalOffset() + GLOBAL_FEATURE_COUNT; }

  int ego(EgoFeature f) const { return static_cast<int>(f); }
  int neighbour(NeighbourSlot s, NeighbourFeature f) const {
    return EGO_FEATURE_COUNT + static_cast<int>(s) * NEIGHBOUR_FEATURE_COUNT + static_cast<int>(f);
  }
  int clusterMeanSpeed() const {
    return EGO_FEATURE_COUNT + NEIGHBOUR_SLOT_COUNT * NEIGHBOUR_FEATURE_COUNT;
  }
  /// Density of paper lane 1..L. Throws std::invalid_argument for any other lane.
  int clusterDensity(int lane) const;
  int global(GlobalFeature f) const { return globalOffset() + static_cast<int>(f); }

  /// Human-readable name of index 0..size()-1 ("ego.speed", "left_follow.lane",
  /// "cluster.density_lane3", "global.upstream"). Throws std::out_of_range otherwise.
  std::string name(int index) const;

 private:
  int globalOffset() const { return clusterMeanSpeed() + 1 + num_lanes_; }
  int num_lanes_;
};

}  // namespace palcas
