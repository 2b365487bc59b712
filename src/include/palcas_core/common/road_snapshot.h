#pragma once
// Plain, ROS-free snapshot of the road at one simulation step: what the RSU knows about
// every vehicle, its cluster, and the other clusters (I2I). Filled from
// palcas_msgs/VehicleStateArray and ClusterState by the RSU's conversion module.
//
// Conventions (README.md, "Conventions"): lanes counted the paper's way, 1 = rightmost (exit) lane ..
// L = leftmost, 0 = not on a mainline lane (on-ramp, acceleration lane, off-ramp);
// x = metres along the mainline from its start; SI units.

#include <string>
#include <vector>

namespace palcas {

/// State of one vehicle at one step (mirrors palcas_msgs/VehicleState).
struct VehicleSnapshot {
  std::string id;
  bool is_cav = false;
  int lane = 1;                      ///< paper lane 1..L, 0 = off the mainline
  double x_m = 0.0;                  ///< front bumper along the mainline [m]
  double lateral_m = 0.0;            ///< centre, from the right edge of lane 1 [m], + = left
  double speed_mps = 0.0;            ///< longitudinal speed [m/s]
  double accel_mps2 = 0.0;           ///< longitudinal acceleration [m/s^2], braking < 0
  double lateral_speed_mps = 0.0;    ///< lateral speed [m/s], + = to the left
  double length_m = 5.0;             ///< [m]
  double width_m = 1.8;              ///< [m]
  double distance_to_exit_m = 0.0;   ///< front bumper to its off-ramp [m]; +inf = no exit
  bool on_accel_lane = false;        ///< on an on-ramp's acceleration lane (then lane == 0)
  double accel_lane_pos_m = 0.0;     ///< position along that acceleration lane [m]
  double accel_lane_length_m = 0.0;  ///< length of that acceleration lane [m]
  double max_speed_mps = 33.528;     ///< the vehicle's own maximum speed [m/s]
  /// A CAV handed back to its own driving by the bridge's guard (busy zone): it is not
  /// advised, since its advice would be dropped; it stays a neighbour in others' states.
  bool driving_itself = false;
};

/// All vehicles one RSU reasons about at one step, on a road of num_lanes mainline lanes.
struct RoadSnapshot {
  int num_lanes = 5;
  std::vector<VehicleSnapshot> vehicles;
};

/// Macroscopic state of the RSU's own cluster (paper "State Space", s_local).
struct ClusterStats {
  double mean_speed_mps = 0.0;
  std::vector<double> lane_density_veh_per_km;  ///< index 0 = lane 1 (rightmost) [veh/km]
};

/// Densities shared over I2I (paper s_global) [veh/km, all lanes of a cluster together].
/// NaN or negative = unknown (no upstream cluster, message not received yet, ...).
struct GlobalDensities {
  double upstream = -1.0;
  double own = -1.0;
  double downstream = -1.0;
};

/// Checks one vehicle against the conventions above for a road of `num_lanes` lanes.
/// Throws std::invalid_argument naming the vehicle id and the field when a field is NaN or
/// infinite (distance_to_exit_m may be +inf), the lane is outside 0..num_lanes, the length
/// or width is not positive, distance_to_exit_m is negative, the id is empty, or
/// on_accel_lane is set on a mainline lane.
void validateVehicle(const VehicleSnapshot& vehicle, int num_lanes);

/// Checks num_lanes >= 1, every vehicle (validateVehicle) and that ids are unique.
/// Throws std::invalid_argument naming what is wrong.
void validateSnapshot(const RoadSnapshot& snapshot);

}  // namespace palcas
