#pragma once
// What the bridge needs to know about the road. Either derived from the SUMO network by the
// edge naming convention of config/scenarios (see config/scenarios/README.md), with x = SUMO's
// x coordinate (a straight road along +x):
//   main_*            mainline edges, running along +x from x = 0
//   main_<k>_merge    the mainline edge of cluster k whose SUMO lane 0 is the acceleration lane
//   on_<k>            the on-ramp of cluster k (joins main_<k>_merge's lane 0)
//   off_<k>           the off-ramp of cluster k (leaves from lane 1, the rightmost main lane)
// or taken from a road found in any network (own_road.h: a user's own road), with x measured
// along the mainline's lanes.

#include <map>
#include <string>
#include <vector>

#include "palcas_core/common/road_terms.h"

namespace palcas::sim {

/// One edge of the network as the bridge sees it.
struct EdgeInfo {
  std::string id;
  RoadPart part = RoadPart::kUnknown;  ///< for a merge edge: kMainline (lane 0 is kAccelLane)
  int cluster = -1;                    ///< cluster index for ramps and merge edges, else -1
  double x_start_m = 0.0;              ///< x of the edge's start along the mainline
  double x_end_m = 0.0;
  int lane_count = 0;                  ///< SUMO lanes on the edge
  bool has_accel_lane = false;         ///< SUMO lane 0 is an acceleration lane
};

/// One RSU zone with its ramps.
struct ClusterInfo {
  int index = 0;
  double x_start_m = 0.0;       ///< zone [x_start_m, x_end_m) along the mainline
  double x_end_m = 0.0;
  std::string on_ramp_edge;     ///< "" when the cluster has no on-ramp
  std::string on_ramp_joins_edge;  ///< the mainline edge the on-ramp joins ("" = its merge edge)
  std::string merge_edge;
  double accel_lane_x_start_m = 0.0;
  double accel_lane_length_m = 0.0;
  std::string off_ramp_edge;    ///< "" when the cluster has no off-ramp
  double exit_x_m = 0.0;        ///< x where the off-ramp leaves the mainline
  std::string exit_from_edge;   ///< the mainline edge the off-ramp leaves from ("" = by x)
};

struct OwnRoad;

/// Classifies edges by name and answers position questions.
class RoadLayout {
 public:
  /// @param edges every edge of the network; @param cluster_length_m zone length (800 m)
  /// @throws std::invalid_argument on a malformed name, a cluster without its merge edge,
  ///         or a non-positive cluster length.
  RoadLayout(std::vector<EdgeInfo> edges, int num_main_lanes, double cluster_length_m);
  /// A road found by discoverOwnRoad (edges already classified, zones given).
  /// @throws std::invalid_argument when it has no mainline.
  explicit RoadLayout(const OwnRoad& road);

  /// @throws std::out_of_range naming the edge when it is not part of the network.
  const EdgeInfo& edge(const std::string& id) const;
  bool hasEdge(const std::string& id) const { return index_.count(id) > 0; }
  const std::vector<ClusterInfo>& clusters() const { return clusters_; }
  int numMainLanes() const { return num_main_lanes_; }
  double mainlineLengthM() const { return mainline_length_m_; }
  double clusterLengthM() const { return cluster_length_m_; }
  /// Cluster whose zone holds x (clamped to the first/last cluster).
  int clusterAt(double x_m) const;
  /// RSU zone (cluster) whose [x_start_m, x_end_m) holds x, as the RSUs split the road;
  /// -1 outside every zone. The session's one zone lookup (the advice guard's too).
  int zoneAt(double x_m) const;
  /// Mainline edges in driving order (a road of the naming convention: ordered by x).
  const std::vector<std::string>& mainline() const { return mainline_; }
  /// true: x is measured along the lanes (xAlongMainline); false: x is SUMO's x coordinate.
  bool measuredAlongLanes() const { return measured_along_lanes_; }
  /// x of a vehicle at `lane_pos_m` on `edge_id` (a junction-internal edge too), measured
  /// along the lanes; `otherwise` for an edge the road does not place.
  double xAlongMainline(const std::string& edge_id, double lane_pos_m, double otherwise) const;
  /// Where a vehicle is on an off-ramp, by edge, with the index of the cluster that off-ramp
  /// belongs to: every cluster's off-ramp edge and, on an own road, the junction-internal
  /// edges from the mainline onto it. Read off the road, never off an edge's name, so an
  /// exit is judged on the vehicle's own off-ramp whatever the edges are called.
  std::map<std::string, int> offRampEdges() const;

  /// Paper lane (1 = rightmost mainline lane .. L; 0 = not on a mainline lane) of a SUMO
  /// lane index on an edge. This is the one place where the conventions meet.
  int paperLane(const std::string& edge_id, int sumo_lane_index) const;
  /// SUMO lane index on `edge_id` of paper lane `lane` (1..L), or -1 if the edge has no
  /// such lane.
  int sumoLaneIndex(const std::string& edge_id, int paper_lane) const;
  /// Paper lanes 1..n a mainline edge has (fewer than L where a lane ends); L for any other
  /// edge or one the road does not place (a junction: the request waits for the next edge).
  int mainLanesOn(const std::string& edge_id) const;

 private:
  /// Zones starting at `zone_starts_m` (each ends where the next starts, the last at the
  /// mainline's end) with the ramps and merge edges of `edges_`.
  void buildClusters(const std::vector<double>& zone_starts_m);

  std::vector<EdgeInfo> edges_;
  std::map<std::string, std::size_t> index_;
  std::vector<std::string> mainline_;
  std::map<std::string, double> internal_x_start_m_;
  std::map<std::string, std::string> onto_off_ramp_;  ///< own road: junction edge -> its off-ramp
  bool measured_along_lanes_ = false;
  std::vector<ClusterInfo> clusters_;
  int num_main_lanes_;
  double cluster_length_m_;
  double mainline_length_m_ = 0.0;
};

/// Route kind and clusters from a route's edges on `road`: the cluster of the first on-ramp
/// and of the first off-ramp among them (-1: none). How an own road's routes are read,
/// whatever their ids: a route's exit is the off-ramp it takes.
void classifyRouteByEdges(const RoadLayout& road, const std::vector<std::string>& edges, RouteKind* kind,
                          int* entry_cluster, int* exit_cluster);

}  // namespace palcas::sim
