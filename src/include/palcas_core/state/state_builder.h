#pragma once
// Builds the normalised per-CAV state vectors (paper "State Space"), one
// column per CAV, from a road snapshot, the cluster statistics and the I2I densities.
// Layout: state_layout.h; table, scales and encodings: src/doc/state_and_reward.md.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "palcas_core/common/road_snapshot.h"
#include "palcas_core/state/neighbours.h"
#include "palcas_core/state/state_layout.h"

namespace palcas {

/// Normalisation scales: feature / scale lands roughly in [-1, 1].
struct StateScales {
  double road_length_m = 2400.0;          ///< ego x: the paper's 2.4 km highway
  double lateral_m = 16.0;                ///< ego lateral position: 5 lanes x 3.2 m
  double speed_mps = 33.528;              ///< all speeds: the speed limit (75 mph)
  double accel_mps2 = 4.5;                ///< all accelerations: |a_min| of the action space
  double sensing_range_m = 200.0;         ///< neighbour gaps; a neighbour beyond it is "empty"
  double exit_range_m = 3000.0;           ///< distances to exit, clipped to [0, 1]; no exit -> 1
  double jam_density_veh_per_km = 150.0;  ///< per-lane density; global uses L x this
};

/// Lane-feature codes of neighbour slots without a vehicle. A real neighbour's lane
/// feature is lane / L in [0, 1], so both codes are distinguishable from any vehicle.
constexpr float EMPTY_SLOT_LANE_CODE = -0.5f;  ///< lane exists, no vehicle within range
constexpr float NO_LANE_CODE = -1.0f;          ///< the lane itself does not exist
/// Global density feature of an unknown (NaN or negative) density; real ones are >= 0.
constexpr float UNKNOWN_DENSITY_CODE = -1.0f;

/// Throws std::invalid_argument naming the first scale that is not finite and > 0.
void validateScales(const StateScales& scales);

/// Stateless state builder for a road of L lanes.
class StateBuilder {
 public:
  /// Throws std::invalid_argument when num_lanes < 1 or a scale is invalid.
  explicit StateBuilder(int num_lanes, const StateScales& scales = StateScales());

  const StateLayout& layout() const { return layout_; }
  const StateScales& scales() const { return scales_; }

  /// One column (layout().size() rows) per id in `cav_ids`, in that order.
  /// Throws std::invalid_argument on an unknown id, a snapshot whose num_lanes differs
  /// from the builder's, cluster densities that are not L finite values >= 0, or a
  /// non-finite cluster mean speed; nothing is returned then.
  Eigen::MatrixXf buildStates(const NeighbourFinder& finder,
                              const std::vector<std::string>& cav_ids, const ClusterStats& cluster,
                              const GlobalDensities& global) const;
  /// Same, indexing `snapshot` first (validates it, see NeighbourFinder).
  Eigen::MatrixXf buildStates(const RoadSnapshot& snapshot, const std::vector<std::string>& cav_ids,
                              const ClusterStats& cluster, const GlobalDensities& global) const;

 private:
  void validateInputs(int snapshot_lanes, const ClusterStats& cluster) const;
  void fillEgo(const VehicleSnapshot& ego, float* column) const;
  void fillNeighbours(const Neighbourhood& hood, float* column) const;
  void fillCluster(const ClusterStats& cluster, const GlobalDensities& global, float* column) const;
  float exitFeature(double distance_to_exit_m) const;

  StateLayout layout_;
  StateScales scales_;
};

/// Convenience: StateBuilder(snapshot.num_lanes, scales).buildStates(...).
Eigen::MatrixXf buildStates(const RoadSnapshot& snapshot, const std::vector<std::string>& cav_ids,
                            const ClusterStats& cluster, const GlobalDensities& global,
                            const StateScales& scales = StateScales());

}  // namespace palcas
