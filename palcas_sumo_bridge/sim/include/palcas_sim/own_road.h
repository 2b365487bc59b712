#pragma once
// A road the user brings (scenario key network_file): any SUMO network with one carriageway,
// edges named as the user likes. What the naming convention of road_layout.h says by name is
// found here from the network's topology instead (rule and restrictions:
// config/scenarios/README.md, "Bring your own road"):
//   mainline   given as an edge list, or found: start at the source edge (no predecessor)
//              with the most lanes, then at each junction follow the successor with the most
//              lanes (ties: the one more lanes connect into; still tied: an error asking for
//              the list);
//   x          metres along the mainline: the cumulative length of its lanes, junction-
//              internal lanes included (curves are measured along the road, not the map);
//   ramps      an on-ramp is a non-mainline edge with a connection into a mainline edge, an
//              off-ramp one with a connection out of a mainline edge; a vehicle on an
//              on-ramp is at x = where it joins minus what it still has to drive on the ramp,
//              on an off-ramp at x = where it leaves plus what it has driven on the ramp;
//   accel lane SUMO lane 0 of a mainline edge that only ramps or another acceleration lane
//              feed (no through lane of the edge before it);
//   lanes      paper lane 1 = the rightmost through lane; L = the most through lanes of any
//              mainline edge (an edge with fewer has no lanes above its count: a lane drop);
//   zones      the mainline split into `clusters` equal zones, or starting where the user
//              says (x or mainline edges: where the roadside units stand); a ramp belongs to
//              the zone holding its junction; at most one on-ramp and one off-ramp per zone;
//   junction   the junction-internal edges from the mainline onto an off-ramp belong to that
//              off-ramp (its exit is judged on them: metrics.md, "OutcomeTracker rules").

#include <map>
#include <string>
#include <vector>

#include "palcas_sim/road_layout.h"

namespace palcas::sim {

/// One edge of a .net.xml (junction-internal edges included, function "internal").
struct NetEdge {
  std::string id;
  std::string from_node;
  std::string to_node;
  bool internal = false;
  int lane_count = 0;
  double length_m = 0.0;  ///< length of its lane 0 (SUMO gives every lane of an edge one length)
};

/// One lane-to-lane connection; `via` is the junction-internal lane it drives through ("" = none).
struct NetLink {
  std::string from_edge;
  int from_lane = 0;
  std::string to_edge;
  int to_lane = 0;
  std::string via;
};

/// The topology of a SUMO network: what discovery needs.
struct NetTopology {
  std::vector<NetEdge> edges;
  std::vector<NetLink> links;                       ///< internal ones included
  std::map<std::string, double> lane_length_m;      ///< every lane, internal ones included
};

/// @throws std::runtime_error when the file cannot be read or is not a SUMO network.
NetTopology readNetTopology(const std::string& net_file);

/// What a scenario says about its own road.
struct OwnRoadOptions {
  std::vector<std::string> mainline_edges;  ///< in driving order; empty = the discovery rule
  int clusters = 1;                         ///< RSU zones the mainline is split into
  /// Where the zones start instead of equal parts (RoadSpec's keys of the same names): x
  /// along the mainline [m], or the mainline edges they start at; at most one, `clusters` long.
  std::vector<double> zone_starts_m;
  std::vector<std::string> zone_start_edges;
};

/// The road found in a network: classified edges for RoadLayout and what the session needs.
struct OwnRoad {
  std::vector<EdgeInfo> edges;             ///< every non-internal edge, classified, x along the mainline
  std::vector<std::string> mainline;       ///< mainline edges in driving order
  std::map<std::string, double> internal_x_start_m;  ///< junction-internal edge -> x where it starts
  std::map<int, std::string> exit_from_edge;         ///< zone -> mainline edge its off-ramp leaves
  std::map<int, std::string> on_ramp_joins_edge;     ///< zone -> mainline edge its on-ramp joins
  /// Junction-internal edge -> the off-ramp it leads onto from the mainline (only edges that
  /// lead nowhere else). A vehicle on one has left the mainline for that off-ramp, however
  /// long the junction lane is (netconvert makes it 30 m and more where a ramp leaves at a
  /// shallow angle).
  std::map<std::string, std::string> onto_off_ramp;
  int num_main_lanes = 0;                  ///< L: most through lanes of a mainline edge
  int clusters = 1;
  double mainline_length_m = 0.0;
  double cluster_length_m = 0.0;           ///< mainline_length_m / clusters (the mean zone length)
  std::vector<double> zone_starts_m;       ///< x where each zone starts: clusters of them, the first 0
};

/// Finds the mainline, positions, ramps, acceleration lanes and zones (rule above).
/// @throws std::invalid_argument naming what is wrong: an unknown or non-connected edge in
///         mainline_edges, no mainline found (or an ambiguous one), clusters < 1, zone
///         starts that do not fit the mainline (not one per zone, not increasing, past its
///         end, an edge not on it), a zone with two on-ramps or two off-ramps, an off-ramp
///         that does not leave from the rightmost lane.
OwnRoad discoverOwnRoad(const NetTopology& net, const OwnRoadOptions& options);

}  // namespace palcas::sim
