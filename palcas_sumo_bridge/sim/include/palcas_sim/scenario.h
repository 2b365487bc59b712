#pragma once
// The paper's SUMO scenario (paper "Simulation Setup"): the network (netconvert on sources
// generated from a RoadSpec, palcas_sim/road_spec.h, or on hand-written ones that follow the
// naming), the demand (vehicle types, routes, flows) and the .sumocfg. Layout, naming and every
// parameter's reason: config/scenarios/README.md; the defaults mirrored as YAML:
// config/scenarios/paper/scenario.yaml.

#include <map>
#include <string>
#include <vector>

#include "palcas_sim/own_road.h"
#include "palcas_sim/road_layout.h"
#include "palcas_sim/road_spec.h"

namespace palcas::sim {

/// Two-point (Bernoulli) maximum-speed distribution: fast_mps with probability p_fast, else
/// slow_mps (paper: "maximum speeds following a Bernoulli distribution"; values are ours).
struct TwoPointSpeed {
  double fast_mps = 33.528;  ///< the paper's speed limit (75 mph)
  double slow_mps = 29.0576; ///< 65 mph; the paper gives no value (README.md)
  double p_fast = 0.5;       ///< in [0, 1]; the paper gives no value (README.md)
};

/// SUMO insertion attributes of a flow (departLane / departPos / departSpeed, SUMO's syntax:
/// a keyword such as "random", "random_free", "max", or a number).
struct InsertionSettings {
  std::string depart_lane;
  std::string depart_pos;
  std::string depart_speed;
};

/// Share of one source's vehicles per destination: key "end" or "off<k>", value in [0, 1];
/// the shares of one source sum to 1.
using RouteShares = std::map<std::string, double>;

/// Default route mix for a road of `num_clusters` clusters (the paper gives none): mainline
/// traffic 0.55 to the end, 0.45 split evenly over every off-ramp; on-ramp k sends 0.6 split
/// evenly over the off-ramps j > k and 0.4 to the end (the last on-ramp: all to the end).
/// Keys are "main" and "on<k>". @throws std::invalid_argument if num_clusters < 1.
std::map<std::string, RouteShares> defaultRouteShares(int num_clusters);

/// Everything that defines one generated scenario. Defaults are the paper's where it gives a
/// value; the others are documented choices (config/scenarios/README.md).
struct ScenarioConfig {
  /// Folder with vtypes.xml, and with network.{nod,edg,con}.xml when generate_network is false.
  std::string scenario_dir;
  /// The road (paper defaults). road.cluster_length_m is the RSU zone length given to RoadLayout;
  /// road.clusters and road.num_lanes must be the network's (checked by buildRoutes).
  RoadSpec road;
  /// true: the network sources are generated from `road` into <out_dir>/sources/; false: the
  /// hand-written <scenario_dir>/network.{nod,edg,con}.xml are used (only road.clusters,
  /// road.num_lanes and road.cluster_length_m are then read).
  bool generate_network = true;
  /// A user's own road, relative to scenario_dir: a SUMO network (*.net.xml, used as it is) or
  /// a netconvert configuration (*.netccfg naming the user's sources, any edge names). The
  /// road is found in it (own_road.h; generate_network is then not read, road.num_lanes must
  /// be its lane count L and road.clusters splits its mainline into equal zones).
  /// "" = generate_network decides (roads of the naming convention).
  std::string network_file;
  /// With network_file: the mainline's edges in driving order; empty = the discovery rule.
  std::vector<std::string> mainline_edges;
  /// With network_file: the user's own routes and flows (relative to scenario_dir), written
  /// into routes.rou.xml after the vehicle types (type "mixed" is there to use) instead of
  /// the demand of this config; "" = routes from the demand below.
  std::string route_file;
  double penetration_rate = 0.6;     ///< CAV share PR in [0, 1] (paper default 60 %)
  unsigned int seed = 42;            ///< SUMO --seed (vehicle types, insertion, sigma)
  double duration_s = 3600.0;        ///< simulated time, SUMO --end (> 0)
  double mainline_flow_vphpl = 3200.0;  ///< veh/h per mainline lane (paper), >= 0
  double onramp_flow_vphpl = 600.0;     ///< veh/h per on-ramp lane (paper), >= 0
  /// Empty: defaultRouteShares(road.clusters).
  std::map<std::string, RouteShares> route_shares;
  TwoPointSpeed cav_speed;           ///< CAV maximum speeds
  TwoPointSpeed hdv_speed;           ///< HDV (the paper's CHV) maximum speeds
  /// Mainline flows start on the 100 m warm-up edge at a random free place (paper: "randomly
  /// insert vehicles" in the warm-up zone), on a random lane, as fast as is safe.
  InsertionSettings mainline_insertion{"random", "random_free", "max"};
  /// On-ramp flows start at the ramp's beginning (one lane), as fast as is safe.
  InsertionSettings onramp_insertion{"first", "base", "max"};
  /// SUMO --max-depart-delay: a vehicle that waited longer for insertion is dropped. The
  /// paper's printed demand exceeds what the lanes carry, so this bounds the queue; < 0 = never drop.
  double max_depart_delay_s = 10.0;
  /// SUMO --time-to-teleport: a vehicle stuck this long is teleported; < 0 = never.
  double time_to_teleport_s = 300.0;
  double step_length_s = 0.1;          ///< paper Table "Hyper/Params"
  double lateral_resolution_m = 3.2;   ///< SL2015 sublane width (paper)
  std::string netconvert_binary = "netconvert";  ///< program run to build the network
};

/// Paths of a generated scenario (all inside the output folder).
struct ScenarioFiles {
  std::string net_file;      ///< network.net.xml
  std::string routes_file;   ///< routes.rou.xml
  std::string sumocfg_file;  ///< scenario.sumocfg (the file to give `sumo -c`)
};

/// One route of the demand and the flow on it.
struct RouteDemand {
  std::string id;                  ///< r_<from>_<to>, from in {main, on<k>}, to in {end, off<k>}
  std::vector<std::string> edges;  ///< SUMO edge ids in driving order
  double vehs_per_hour = 0.0;      ///< source flow x share (0: route written, no flow)
  bool from_ramp = false;          ///< the flow uses onramp_insertion
};

/// Probabilities of the four vehicle types, from PR and the two p_fast values:
/// cav_fast = PR p_cav, cav_slow = PR (1 - p_cav), hdv_fast = (1 - PR) p_hdv,
/// hdv_slow = (1 - PR)(1 - p_hdv).
struct VTypeProbabilities {
  double cav_fast = 0.0, cav_slow = 0.0, hdv_fast = 0.0, hdv_slow = 0.0;
};

/// True for the CAV vehicle types (their id starts with "cav").
inline bool isCavType(const std::string& type_id) { return type_id.rfind("cav", 0) == 0; }

/// Checks every scalar field, the insertion keywords and the road (validateRoadSpec when
/// generate_network, else road.clusters, road.num_lanes and road.cluster_length_m); not the
/// route shares, which need the network. @throws std::invalid_argument naming the field and
/// the bad value.
void validateScenarioConfig(const ScenarioConfig& config);

/// @throws std::invalid_argument as validateScenarioConfig.
VTypeProbabilities vTypeProbabilities(const ScenarioConfig& config);

/// Every route of the network with its flow (route shares checked against the network; empty
/// route_shares = defaultRouteShares(road.clusters)).
/// @param edges the network's edges (readNetEdges). @throws std::invalid_argument naming the
///        source or destination when a share is missing, unknown, negative, upstream of its
///        source, or a source's shares do not sum to 1 (tolerance 1e-6); when the mainline
///        has a gap or lanes of differing count; or when the network's cluster or lane count is
///        not road.clusters / road.num_lanes.
std::vector<RouteDemand> buildRoutes(const ScenarioConfig& config,
                                     const std::vector<EdgeInfo>& edges);

/// What discoverOwnRoad needs from a config with network_file (mainline_edges, road.clusters).
OwnRoadOptions ownRoadOptions(const ScenarioConfig& config);

/// Routes of an own road (config.network_file) with their flows: the mainline's first edge
/// to its last and to every off-ramp; each on-ramp to the last edge and to every off-ramp
/// that leaves after its acceleration lane ends (or after it joins). Ids r_<from>_<to> with
/// the zones' indices (main, on<k>; end, off<k>), edges the network's own. Route shares
/// empty: the default rule over the ramps there are (0.55 of the mainline's traffic to the
/// end, 0.45 over its exits; an on-ramp's 0.6 over its exits, 0.4 to the end).
/// @throws std::invalid_argument as buildRoutes for the shares, and when the road's lane
///         count is not road.num_lanes.
std::vector<RouteDemand> buildOwnRoadRoutes(const ScenarioConfig& config, const OwnRoad& road);

/// The network of an own road into <out_dir>/network.net.xml: a *.net.xml copied, a
/// *.netccfg run through netconvert (its paths are relative to it). @return the path.
/// @throws std::invalid_argument naming the file when it does not exist or is of another
///         kind; std::runtime_error with netconvert's output when it fails.
std::string prepareOwnNetwork(const ScenarioConfig& config, const std::string& out_dir);

/// Runs netconvert on <scenario_dir>/network.{nod,edg,con}.xml into <out_dir>/network.net.xml
/// (creating out_dir). @return the .net.xml path. @throws std::invalid_argument when a source
/// file is missing; std::runtime_error with netconvert's output when it fails.
std::string generateNetwork(const std::string& scenario_dir, const std::string& out_dir,
                            const std::string& netconvert_binary = "netconvert");

/// writeNetworkSources(road, <out_dir>/sources), then netconvert on them into
/// <out_dir>/network.net.xml. @return the .net.xml path. @throws std::invalid_argument for a
/// bad spec (nothing written); std::runtime_error as generateNetwork or writeNetworkSources.
std::string generateNetwork(const RoadSpec& road, const std::string& out_dir,
                            const std::string& netconvert_binary = "netconvert");

/// Non-internal edges of a SUMO .net.xml: id, lane count, x_start_m / x_end_m = x of the first
/// / last point of lane 0's shape (the mainline runs along +x, so x is the mainline position).
/// part / cluster / has_accel_lane are left for RoadLayout to classify.
/// @throws std::runtime_error when the file cannot be read or is not a SUMO network.
std::vector<EdgeInfo> readNetEdges(const std::string& net_file);

/// One lane-to-lane connection of a network (SUMO lane indices).
struct LaneConnection {
  std::string from_edge;
  int from_lane = 0;
  std::string to_edge;
  int to_lane = 0;
};

/// Connections between non-internal edges of a SUMO .net.xml.
/// @throws std::runtime_error as readNetEdges.
std::vector<LaneConnection> readNetConnections(const std::string& net_file);

/// Generates the whole scenario into out_dir: network.net.xml (netconvert on the sources
/// generated from config.road into out_dir/sources/, or on the hand-written ones),
/// routes.rou.xml (vTypeDistribution "mixed" of cav_fast, cav_slow, hdv_fast, hdv_slow built from
/// <scenario_dir>/vtypes.xml; one route per origin-destination pair; one flow per route with a
/// non-zero share) and scenario.sumocfg (no output files).
/// @throws std::invalid_argument for a bad config (nothing is written: the scalar checks run
///         first; a route-share error is found after netconvert, and then only the network
///         file and its sources exist); std::runtime_error when netconvert fails or a file
///         cannot be written.
ScenarioFiles writeScenario(const ScenarioConfig& config, const std::string& out_dir);

}  // namespace palcas::sim
