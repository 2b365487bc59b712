#include "palcas_core/state/state_builder.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "palcas_core/common/checks.h"

namespace palcas {
namespace {

float clip(double value) { return static_cast<float>(std::clamp(value, -1.0, 1.0)); }

}  // namespace

void validateScales(const StateScales& s) {
  using common::requirePositive;
  requirePositive(s.road_length_m, "StateScales.road_length_m");
  requirePositive(s.lateral_m, "StateScales.lateral_m");
  requirePositive(s.speed_mps, "StateScales.speed_mps");
  requirePositive(s.accel_mps2, "StateScales.accel_mps2");
  requirePositive(s.sensing_range_m, "StateScales.sensing_range_m");
  requirePositive(s.exit_range_m, "StateScales.exit_range_m");
  requirePositive(s.jam_density_veh_per_km, "StateScales.jam_density_veh_per_km");
}

StateBuilder::StateBuilder(int num_lanes, const StateScales& scales)
    : layout_(num_lanes), scales_(scales) {
  validateScales(scales_);
}

void StateBuilder::validateInputs(int snapshot_lanes, const ClusterStats& cluster) const {
  const int lanes = layout_.numLanes();
  if (snapshot_lanes != lanes)
    throw std::invalid_argument("snapshot has " + std::to_string(snapshot_lanes) +
                                " lanes, the state builder " + std::to_string(lanes));
  if (!std::isfinite(cluster.mean_speed_mps))
    throw std::invalid_argument("ClusterStats.mean_speed_mps is not finite");
  if (static_cast<int>(cluster.lane_density_veh_per_km.size()) != lanes)
    throw std::invalid_argument("ClusterStats.lane_density_veh_per_km has " +
                                std::to_string(cluster.lane_density_veh_per_km.size()) +
                                " values, expected one per lane (" + std::to_string(lanes) + ")");
  for (size_t i = 0; i < cluster.lane_density_veh_per_km.size(); ++i) {
    const double d = cluster.lane_density_veh_per_km[i];
    if (!std::isfinite(d) || d < 0.0)
      throw std::invalid_argument("ClusterStats.lane_density_veh_per_km[" + std::to_string(i) +
                                  "] must be finite and >= 0");
  }
}

// Distance to exit: d / exit_range clipped to [0, 1]; +inf (no exit) -> 1, the same as
// an exit beyond the range: both mean "no exit pressure".
float StateBuilder::exitFeature(double distance_to_exit_m) const {
  if (std::isinf(distance_to_exit_m)) return 1.0f;
  return static_cast<float>(std::clamp(distance_to_exit_m / scales_.exit_range_m, 0.0, 1.0));
}

void StateBuilder::fillEgo(const VehicleSnapshot& ego, float* c) const {
  const double lanes = layout_.numLanes();
  c[layout_.ego(EgoFeature::kLongitudinal)] = static_cast<float>(ego.x_m / scales_.road_length_m);
  c[layout_.ego(EgoFeature::kLateral)] = static_cast<float>(ego.lateral_m / scales_.lateral_m);
  c[layout_.ego(EgoFeature::kSpeed)] = static_cast<float>(ego.speed_mps / scales_.speed_mps);
  c[layout_.ego(EgoFeature::kAccel)] = static_cast<float>(ego.accel_mps2 / scales_.accel_mps2);
  c[layout_.ego(EgoFeature::kLane)] = static_cast<float>(ego.lane / lanes);  // ramp: 0
  c[layout_.ego(EgoFeature::kDistanceToExit)] = exitFeature(ego.distance_to_exit_m);
}

// Real neighbour: [gap / range (clipped), v / v_scale, a / a_scale, lane / L, exit].
// Empty slot (no vehicle within the sensing range): [1, 0, 0, -0.5, 1] = free road.
// Missing lane: [0, 0, 0, -1, 1] = a wall right beside the ego.
void StateBuilder::fillNeighbours(const Neighbourhood& hood, float* c) const {
  const double lanes = layout_.numLanes();
  for (int s = 0; s < NEIGHBOUR_SLOT_COUNT; ++s) {
    const auto slot = static_cast<NeighbourSlot>(s);
    const auto at = [&](NeighbourFeature f) -> float& { return c[layout_.neighbour(slot, f)]; };
    const auto& n = hood.slot[s];
    const bool lane_exists = hood.lane[s / 2] != NO_LANE;
    if (n && n->gap_m <= scales_.sensing_range_m) {
      at(NeighbourFeature::kRelativeDistance) = clip(n->gap_m / scales_.sensing_range_m);
      at(NeighbourFeature::kSpeed) = static_cast<float>(n->vehicle->speed_mps / scales_.speed_mps);
      at(NeighbourFeature::kAccel) =
          static_cast<float>(n->vehicle->accel_mps2 / scales_.accel_mps2);
      at(NeighbourFeature::kLane) = static_cast<float>(n->vehicle->lane / lanes);
      at(NeighbourFeature::kDistanceToExit) = exitFeature(n->vehicle->distance_to_exit_m);
    } else {
      at(NeighbourFeature::kRelativeDistance) = lane_exists ? 1.0f : 0.0f;
      at(NeighbourFeature::kSpeed) = 0.0f;
      at(NeighbourFeature::kAccel) = 0.0f;
      at(NeighbourFeature::kLane) = lane_exists ? EMPTY_SLOT_LANE_CODE : NO_LANE_CODE;
      at(NeighbourFeature::kDistanceToExit) = 1.0f;
    }
  }
}

// Cluster densities are per lane / jam density; global densities are all lanes of a
// cluster together (ClusterState.density_veh_per_km) / (L x jam density).
void StateBuilder::fillCluster(const ClusterStats& cluster, const GlobalDensities& global,
                               float* c) const {
  const int lanes = layout_.numLanes();
  c[layout_.clusterMeanSpeed()] = static_cast<float>(cluster.mean_speed_mps / scales_.speed_mps);
  for (int lane = 1; lane <= lanes; ++lane)
    c[layout_.clusterDensity(lane)] = static_cast<float>(cluster.lane_density_veh_per_km[lane - 1] /
                                                         scales_.jam_density_veh_per_km);
  const double global_scale = lanes * scales_.jam_density_veh_per_km;
  const auto encode = [&](double d) {
    // NaN, negative and infinite all mean "not known" (no such cluster, no message yet).
    if (!std::isfinite(d) || d < 0.0) return UNKNOWN_DENSITY_CODE;
    return static_cast<float>(d / global_scale);
  };
  c[layout_.global(GlobalFeature::kUpstream)] = encode(global.upstream);
  c[layout_.global(GlobalFeature::kOwn)] = encode(global.own);
  c[layout_.global(GlobalFeature::kDownstream)] = encode(global.downstream);
}

Eigen::MatrixXf StateBuilder::buildStates(const NeighbourFinder& finder,
                                          const std::vector<std::string>& cav_ids,
                                          const ClusterStats& cluster,
                                          const GlobalDensities& global) const {
  validateInputs(finder.numLanes(), cluster);
  Eigen::MatrixXf states(layout_.size(), static_cast<Eigen::Index>(cav_ids.size()));
  for (size_t col = 0; col < cav_ids.size(); ++col) {
    const Neighbourhood hood = finder.find(cav_ids[col]);  // throws on an unknown id
    float* c = states.col(static_cast<Eigen::Index>(col)).data();
    fillEgo(*hood.ego, c);
    fillNeighbours(hood, c);
    fillCluster(cluster, global, c);
  }
  return states;
}

Eigen::MatrixXf StateBuilder::buildStates(const RoadSnapshot& snapshot,
                                          const std::vector<std::string>& cav_ids,
                                          const ClusterStats& cluster,
                                          const GlobalDensities& global) const {
  validateInputs(snapshot.num_lanes, cluster);
  return buildStates(NeighbourFinder(snapshot), cav_ids, cluster, global);
}

Eigen::MatrixXf buildStates(const RoadSnapshot& snapshot, const std::vector<std::string>& cav_ids,
                            const ClusterStats& cluster, const GlobalDensities& global,
                            const StateScales& scales) {
  return StateBuilder(snapshot.num_lanes, scales).buildStates(snapshot, cav_ids, cluster, global);
}

}  // namespace palcas
