#pragma once
// Macroscopic statistics of one RSU's cluster zone (paper "State Space", s_local; shared
// with the other RSUs over I2I as palcas_msgs/ClusterState).

#include <cstdint>
#include <vector>

#include "palcas_core/common/road_snapshot.h"

namespace palcas::rsu {

/// What one RSU publishes about its zone [x_start_m, x_end_m) at one decision.
/// Counted population: vehicles (CAVs and HDVs) on a MAINLINE lane 1..L whose front bumper
/// x_m lies in the zone. Ramp and acceleration-lane vehicles are not counted, so the mean
/// speed and the lane densities describe the same vehicles (src/doc/rsu.md, "Cluster
/// statistics").
struct ClusterSummary {
  /// Mean speed of the counted vehicles [m/s]; the configured empty-zone speed when none.
  double mean_speed_mps = 0.0;
  /// Per-lane density, index 0 = lane 1 (rightmost) [veh/km]: count / zone length.
  std::vector<double> lane_density_veh_per_km;
  /// All lanes together [veh/km] = sum of the lane densities (ClusterState.density_veh_per_km).
  double density_veh_per_km = 0.0;
  uint32_t vehicle_count = 0;  ///< counted vehicles
  uint32_t cav_count = 0;      ///< counted vehicles that are CAVs

  /// The part the state builder and the reward use.
  ClusterStats toClusterStats() const { return {mean_speed_mps, lane_density_veh_per_km}; }
};

/// Statistics of zone [x_start_m, x_end_m) of `snapshot` (see ClusterSummary):
///   mean speed  v_bar = (1/N) sum_i v_i                      (paper s_local, average speed)
///   density     k_l   = N_l / ((x_end_m - x_start_m) / 1000)  [veh/km], l = 1..L
/// empty_zone_speed_mps is reported as the mean speed of an empty zone (free flow).
/// Preconditions: the snapshot is valid (validateSnapshot; not re-checked here).
/// Throws std::invalid_argument when the bounds are not finite or x_end_m <= x_start_m,
/// or empty_zone_speed_mps is not finite and >= 0.
ClusterSummary computeClusterSummary(const RoadSnapshot& snapshot, double x_start_m,
                                     double x_end_m, double empty_zone_speed_mps);

}  // namespace palcas::rsu
