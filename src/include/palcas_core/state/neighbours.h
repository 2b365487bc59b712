#pragma once
// Lead and follower of a vehicle in its own, left and right lanes, served from an index
// sorted by (lane, x) that is built once per snapshot: a whole cluster of CAVs costs
// O(N log N), not O(N^2).

#include <array>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "palcas_core/common/road_snapshot.h"

namespace palcas {

/// The six neighbour slots of the state (paper "State Space", s_sur), in state order.
enum class NeighbourSlot : int {
  kOwnLead = 0,
  kOwnFollow = 1,
  kLeftLead = 2,
  kLeftFollow = 3,
  kRightLead = 4,
  kRightFollow = 5
};
constexpr int NEIGHBOUR_SLOT_COUNT = 6;

/// Which lane relative to the ego: own, left (lane + 1), right (lane - 1).
enum class Side : int { kOwn = 0, kLeft = 1, kRight = 2 };
constexpr int SIDE_COUNT = 3;

/// Lane number used for "this lane does not exist" (left of lane L, right of lane 1, ...).
constexpr int NO_LANE = -1;

/// One neighbour and its bumper-to-bumper gap to the ego [m] (negative = overlap):
/// lead: lead.x - lead.length - ego.x; follower: ego.x - ego.length - follow.x.
struct Neighbour {
  const VehicleSnapshot* vehicle = nullptr;  ///< points into the NeighbourFinder
  double gap_m = 0.0;
};

/// The neighbours of one ego vehicle.
struct Neighbourhood {
  const VehicleSnapshot* ego = nullptr;
  /// Paper lane number of the own / left / right lane, NO_LANE when it does not exist.
  /// Own lane of a ramp vehicle is 0.
  std::array<int, SIDE_COUNT> lane{{NO_LANE, NO_LANE, NO_LANE}};
  /// Empty optional = no vehicle in that position (or the lane does not exist).
  std::array<std::optional<Neighbour>, NEIGHBOUR_SLOT_COUNT> slot;

  int laneOf(Side side) const { return lane[static_cast<int>(side)]; }
  const std::optional<Neighbour>& at(NeighbourSlot s) const { return slot[static_cast<int>(s)]; }
};

/// Lead slot and follower slot of a side.
NeighbourSlot leadSlot(Side side);
NeighbourSlot followSlot(Side side);

/// Index of one snapshot for neighbour queries. Keeps its own copy of the vehicles, so
/// the snapshot passed in may go away; pointers in the answers point into this object.
///
/// Lane topology: a mainline vehicle in lane l has left lane l+1 and right lane l-1 when
/// they are within 1..L. A vehicle on the acceleration lane (lane 0, on_accel_lane) has
/// lane 1 as its left lane and no right lane; its own-lane neighbours are the other
/// acceleration-lane vehicles. Other off-mainline vehicles (on-/off-ramp proper) only
/// see each other, in their own lane, and have no left or right lane. Ties in x: a
/// vehicle in another lane exactly level with the ego counts as its lead.
class NeighbourFinder {
 public:
  /// Validates the snapshot (validateSnapshot) and builds the index, O(N log N).
  /// Throws std::invalid_argument naming the vehicle and field of any bad input.
  explicit NeighbourFinder(const RoadSnapshot& snapshot);

  /// Neighbours of vehicle `ego_id`, O(log N). Throws std::invalid_argument on an
  /// unknown id. The answer points into this finder, so asking a temporary is an error.
  Neighbourhood find(const std::string& ego_id) const&;
  Neighbourhood find(const std::string& ego_id) const&& = delete;

  /// The stored vehicle `id`. Throws std::invalid_argument on an unknown id.
  const VehicleSnapshot& vehicle(const std::string& id) const;

  int numLanes() const { return num_lanes_; }

 private:
  int groupOf(const VehicleSnapshot& v) const;
  void fillSide(const VehicleSnapshot& ego, Side side, int group, Neighbourhood& out) const;

  int num_lanes_;
  std::vector<VehicleSnapshot> vehicles_;
  std::vector<int> sorted_;                        ///< vehicle indices by (group, x, id)
  std::vector<int> group_begin_;                   ///< first sorted_ position per group
  std::unordered_map<std::string, int> position_;  ///< id -> position in sorted_
};

}  // namespace palcas
