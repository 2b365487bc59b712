#pragma once
// The road as data: a RoadSpec describes a road of the paper's shape and writeNetworkSources
// turns it into the netconvert sources network.{nod,edg,con}.xml, following the naming
// convention and geometry of config/scenarios/README.md (RoadLayout reads them back).
//
// Geometry, with L = num_lanes, w = lane_width_m, x0 = k * cluster_length_m for cluster k:
//   mainline along +x at y = 0 (its left border; lanes at negative y). Every mainline node but
//   the first and last has the custom shape "x,0 x,-(L + 1) w" (a line across the road, the
//   merge edge's L + 1 lanes included), so netconvert does not cut edges back around junctions.
//   Ramps drop 1.25 road widths (1.25 L w) from the mainline edge they join or leave:
//   on_k   "x0,y_on - 1.25 L w  x0 + m - p,y_on  x0 + m,y_on", y_on = -(L + 0.5) w (centre of the
//          acceleration lane), m = merge_start_m, p = min(30, m / 3) m parallel to the road;
//   off_k  "x0 + e,y_off  x0 + cluster_length_m,y_off - 1.25 L w", y_off = -(L - 0.5) w (centre
//          of SUMO lane 0), e = exit_m.
// The paper road (defaults) and the tiny road (2 x 300 m, 3 lanes) come out as the former
// hand-written sources of config/scenarios/{paper,tiny} (sim/test/data/hand_written_*).

#include <string>
#include <vector>

namespace palcas::sim {

/// One road of the paper's shape: `clusters` identical clusters of `cluster_length_m`, each with an
/// on-ramp joining through an acceleration lane and an off-ramp; mainline of `num_lanes` lanes.
struct RoadSpec {
  int clusters = 3;                    ///< RSU zones (paper 3)
  int num_lanes = 5;                   ///< mainline lanes L (paper 5)
  double cluster_length_m = 800.0;     ///< zone length (paper 0.8 km)
  double warmup_length_m = 100.0;      ///< main_0_warmup [0, warmup) where mainline traffic is inserted
  double merge_start_m = 150.0;        ///< from the cluster start: where the on-ramp joins
  double acceleration_lane_m = 250.0;  ///< acceleration-lane length
  double exit_m = 700.0;               ///< from the cluster start: where the off-ramp leaves
  double lane_width_m = 3.2;
  double speed_limit_mps = 33.528;     ///< mainline (paper 75 mph)
  double ramp_speed_limit_mps = 22.352;///< ramps (ours, 50 mph)
  /// A road the user brings (network_file) only: where each RSU zone starts, as x along the
  /// mainline [m] (the first 0, increasing) or as the mainline edges it starts at (the first
  /// the mainline's first), one per zone, instead of `clusters` equal parts. At most one of
  /// the two; its length must be `clusters`. A generated road's zones are its clusters.
  std::vector<double> zone_starts_m;
  std::vector<std::string> zone_start_edges;
};

/// Checks every field (zone_starts_m and zone_start_edges must be empty). Bounds: 1 <= clusters <= 100, 1 <= num_lanes <= 10, every number finite,
/// 0 < cluster_length_m <= 100000, lane_width_m in (0, 10], speeds in (0, 100] m/s, and every
/// edge at least 1 m long: 1 <= warmup_length_m, warmup_length_m + 1 <= merge_start_m,
/// 1 <= acceleration_lane_m, merge_start_m + acceleration_lane_m + 1 <= exit_m,
/// exit_m + 1 <= cluster_length_m.
/// @throws std::invalid_argument naming the field ("road/<field>") and the bad value.
void validateRoadSpec(const RoadSpec& road);
/// Zone boundaries [0, L_c, 2 L_c, ..., clusters L_c].
/// @throws std::invalid_argument when clusters or cluster_length_m is out of bounds (the
///         other fields are not needed here and not checked).
std::vector<double> zoneBoundaries(const RoadSpec& road);
/// Writes <dir>/network.nod.xml, network.edg.xml, network.con.xml (creating dir) following the naming
/// convention of config/scenarios/README.md. Validates first (nothing written on a bad spec).
/// @throws std::invalid_argument (bad spec), std::runtime_error (cannot write, naming the path).
void writeNetworkSources(const RoadSpec& road, const std::string& dir);

}  // namespace palcas::sim
