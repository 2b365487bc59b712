#include "palcas_core/state/neighbours.h"

#include <algorithm>
#include <stdexcept>
#include <tuple>

namespace palcas {

NeighbourSlot leadSlot(Side side) { return static_cast<NeighbourSlot>(2 * static_cast<int>(side)); }
NeighbourSlot followSlot(Side side) {
  return static_cast<NeighbourSlot>(2 * static_cast<int>(side) + 1);
}

// Groups: 0 = acceleration lanes, 1..L = mainline lanes, L+1 = other off-mainline
// vehicles (ramps proper), which are nobody's side neighbours.
int NeighbourFinder::groupOf(const VehicleSnapshot& v) const {
  if (v.lane >= 1) return v.lane;
  return v.on_accel_lane ? 0 : num_lanes_ + 1;
}

NeighbourFinder::NeighbourFinder(const RoadSnapshot& snapshot)
    : num_lanes_(snapshot.num_lanes), vehicles_(snapshot.vehicles) {
  validateSnapshot(snapshot);
  sorted_.resize(vehicles_.size());
  for (size_t i = 0; i < sorted_.size(); ++i) sorted_[i] = static_cast<int>(i);
  std::sort(sorted_.begin(), sorted_.end(), [this](int a, int b) {
    const auto& va = vehicles_[a];
    const auto& vb = vehicles_[b];
    return std::make_tuple(groupOf(va), va.x_m, va.id) <
           std::make_tuple(groupOf(vb), vb.x_m, vb.id);
  });
  const int groups = num_lanes_ + 2;
  group_begin_.assign(groups + 1, 0);
  for (int idx : sorted_) ++group_begin_[groupOf(vehicles_[idx]) + 1];
  for (int g = 0; g < groups; ++g) group_begin_[g + 1] += group_begin_[g];
  position_.reserve(sorted_.size());
  for (size_t pos = 0; pos < sorted_.size(); ++pos)
    position_.emplace(vehicles_[sorted_[pos]].id, static_cast<int>(pos));
}

const VehicleSnapshot& NeighbourFinder::vehicle(const std::string& id) const {
  const auto it = position_.find(id);
  if (it == position_.end()) throw std::invalid_argument("unknown vehicle id '" + id + "'");
  return vehicles_[sorted_[it->second]];
}

// Lead = first vehicle of the group at or ahead of the ego (ego itself excluded),
// follower = the one just behind it.
void NeighbourFinder::fillSide(const VehicleSnapshot& ego, Side side, int group,
                               Neighbourhood& out) const {
  const auto begin = sorted_.begin() + group_begin_[group];
  const auto end = sorted_.begin() + group_begin_[group + 1];
  auto lead = end;
  auto follow = end;
  if (side == Side::kOwn) {
    const auto self = sorted_.begin() + position_.at(ego.id);
    lead = self + 1;
    if (self != begin) follow = self - 1;
  } else {
    lead = std::lower_bound(begin, end, ego.x_m,
                            [this](int idx, double x) { return vehicles_[idx].x_m < x; });
    if (lead != begin) follow = lead - 1;
  }
  if (lead != end) {
    const VehicleSnapshot& l = vehicles_[*lead];
    out.slot[static_cast<int>(leadSlot(side))] = Neighbour{&l, l.x_m - l.length_m - ego.x_m};
  }
  if (follow != end) {
    const VehicleSnapshot& f = vehicles_[*follow];
    out.slot[static_cast<int>(followSlot(side))] = Neighbour{&f, ego.x_m - ego.length_m - f.x_m};
  }
}

Neighbourhood NeighbourFinder::find(const std::string& ego_id) const& {
  const VehicleSnapshot& ego = vehicle(ego_id);
  Neighbourhood out;
  out.ego = &ego;
  const int group = groupOf(ego);
  out.lane[static_cast<int>(Side::kOwn)] = ego.lane;
  fillSide(ego, Side::kOwn, group, out);
  int left = NO_LANE;
  int right = NO_LANE;
  if (group == 0) {
    left = 1;  // acceleration lane merges into lane 1
  } else if (group <= num_lanes_) {
    if (ego.lane + 1 <= num_lanes_) left = ego.lane + 1;
    if (ego.lane - 1 >= 1) right = ego.lane - 1;
  }
  out.lane[static_cast<int>(Side::kLeft)] = left;
  out.lane[static_cast<int>(Side::kRight)] = right;
  if (left != NO_LANE) fillSide(ego, Side::kLeft, left, out);
  if (right != NO_LANE) fillSide(ego, Side::kRight, right, out);
  return out;
}

}  // namespace palcas
