// Demand half of the scenario: checking a ScenarioConfig, the vehicle-type mix and the routes
// with their flows. Reasons for every default: config/scenarios/README.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "palcas_sim/scenario.h"
#include "road_checks.h"

namespace palcas::sim {
namespace {

constexpr double SHARE_SUM_TOLERANCE = 1e-6;
constexpr double X_TOLERANCE_M = 0.01;  // netconvert writes coordinates with 2 decimals

/// A number for messages (10 significant digits).
std::string num(double v) {
  std::ostringstream out;
  out.precision(10);
  out << v;
  return out.str();
}

void requireFinite(double v, const std::string& field) {
  if (!std::isfinite(v))
    throw std::invalid_argument("ScenarioConfig." + field + " must be finite, got " +
                                std::to_string(v));
}

void requireInRange(double v, double lo, double hi, const std::string& field) {
  requireFinite(v, field);
  if (v < lo || v > hi)
    throw std::invalid_argument("ScenarioConfig." + field + " must be in [" + std::to_string(lo) +
                                ", " + std::to_string(hi) + "], got " + std::to_string(v));
}

void requirePositive(double v, const std::string& field) {
  requireFinite(v, field);
  if (!(v > 0.0))
    throw std::invalid_argument("ScenarioConfig." + field + " must be > 0, got " +
                                std::to_string(v));
}

bool isNumber(const std::string& s) {
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    return used == s.size() && std::isfinite(v);
  } catch (const std::exception&) {
    return false;
  }
}

/// SUMO's keywords for one depart attribute, or a number.
void requireDepartValue(const std::string& v, const std::vector<std::string>& keywords,
                        const std::string& field) {
  if (isNumber(v) || std::find(keywords.begin(), keywords.end(), v) != keywords.end()) return;
  std::string list;
  for (const std::string& k : keywords) list += (list.empty() ? "" : ", ") + k;
  throw std::invalid_argument("ScenarioConfig." + field + " = '" + v +
                              "' is neither a number nor one of: " + list);
}

void validateInsertion(const InsertionSettings& s, const std::string& field) {
  requireDepartValue(s.depart_lane, {"random", "free", "allowed", "best", "first"},
                     field + ".depart_lane");
  requireDepartValue(s.depart_pos, {"random", "free", "random_free", "base", "last"},
                     field + ".depart_pos");
  requireDepartValue(s.depart_speed, {"random", "max", "desired", "speedLimit", "last", "avg"},
                     field + ".depart_speed");
}

void validateSpeed(const TwoPointSpeed& s, const std::string& field) {
  requirePositive(s.fast_mps, field + ".fast_mps");
  requirePositive(s.slow_mps, field + ".slow_mps");
  if (s.slow_mps > s.fast_mps)
    throw std::invalid_argument("ScenarioConfig." + field + ": slow_mps " +
                                std::to_string(s.slow_mps) + " exceeds fast_mps " +
                                std::to_string(s.fast_mps));
  requireInRange(s.p_fast, 0.0, 1.0, field + ".p_fast");
}

/// Shares of `source` checked against its allowed destinations; returns them.
const RouteShares& checkedShares(const std::map<std::string, RouteShares>& route_shares,
                                 const std::string& source,
                                 const std::vector<std::string>& destinations) {
  const auto it = route_shares.find(source);
  if (it == route_shares.end())
    throw std::invalid_argument("ScenarioConfig.route_shares has no entry for source '" + source + "'");
  double sum = 0.0;
  for (const auto& [to, share] : it->second) {
    if (std::find(destinations.begin(), destinations.end(), to) == destinations.end())
      throw std::invalid_argument("ScenarioConfig.route_shares['" + source +
                                  "']: '" + to + "' is not a destination reachable from it");
    requireInRange(share, 0.0, 1.0, "route_shares['" + source + "']['" + to + "']");
    sum += share;
  }
  if (std::abs(sum - 1.0) > SHARE_SUM_TOLERANCE)
    throw std::invalid_argument("ScenarioConfig.route_shares['" + source + "'] sums to " +
                                std::to_string(sum) + ", not 1");
  return it->second;
}

double shareOf(const RouteShares& shares, const std::string& to) {
  const auto it = shares.find(to);
  return it == shares.end() ? 0.0 : it->second;
}

/// Mainline edges ordered by x, checked to be contiguous with the same number of through lanes
/// (a merge edge's acceleration lane is not a through lane).
std::vector<EdgeInfo> orderedMainline(const RoadLayout& road, const std::vector<EdgeInfo>& edges) {
  std::vector<EdgeInfo> main;
  for (const EdgeInfo& e : edges)
    if (road.edge(e.id).part == RoadPart::kMainline) main.push_back(road.edge(e.id));
  if (main.empty()) throw std::invalid_argument("network has no mainline (main_*) edge");
  std::sort(main.begin(), main.end(),
            [](const EdgeInfo& a, const EdgeInfo& b) { return a.x_start_m < b.x_start_m; });
  for (std::size_t i = 0; i < main.size(); ++i) {
    if (i > 0 && std::abs(main[i].x_start_m - main[i - 1].x_end_m) > X_TOLERANCE_M)
      throw std::invalid_argument("mainline has a gap between '" + main[i - 1].id + "' and '" +
                                  main[i].id + "'");
    const int lanes = main[i].lane_count - (main[i].has_accel_lane ? 1 : 0);
    if (lanes != road.numMainLanes())
      throw std::invalid_argument("mainline edge '" + main[i].id + "' has " +
                                  std::to_string(lanes) + " through lanes, '" + main[0].id +
                                  "' has " + std::to_string(road.numMainLanes()));
  }
  return main;
}

/// Mainline edge ids whose x range lies inside [x_from, x_to].
std::vector<std::string> mainlineBetween(const std::vector<EdgeInfo>& main, double x_from, double x_to) {
  std::vector<std::string> ids;
  for (const EdgeInfo& e : main)
    if (e.x_start_m >= x_from - X_TOLERANCE_M && e.x_end_m <= x_to + X_TOLERANCE_M) ids.push_back(e.id);
  return ids;
}

}  // namespace

std::map<std::string, RouteShares> defaultRouteShares(int num_clusters) {
  if (num_clusters < 1)
    throw std::invalid_argument("defaultRouteShares: need at least one cluster, got " +
                                std::to_string(num_clusters));
  std::map<std::string, RouteShares> shares;
  shares["main"]["end"] = 0.55;
  for (int k = 0; k < num_clusters; ++k) shares["main"]["off" + std::to_string(k)] = 0.45 / num_clusters;
  for (int k = 0; k < num_clusters; ++k) {
    RouteShares& on = shares["on" + std::to_string(k)];
    const int downstream_exits = num_clusters - 1 - k;
    on["end"] = downstream_exits > 0 ? 0.4 : 1.0;
    for (int j = k + 1; j < num_clusters; ++j) on["off" + std::to_string(j)] = 0.6 / downstream_exits;
  }
  return shares;
}

void validateScenarioConfig(const ScenarioConfig& c) {
  if (c.scenario_dir.empty()) throw std::invalid_argument("ScenarioConfig.scenario_dir is empty");
  if (!c.network_file.empty()) {  // an own road: its zone count and lane count
    detail::validateRoadZones(c.road);
    detail::validateZoneStarts(c.road);
    detail::validateRoadLanes(c.road);
    for (const std::string& id : c.mainline_edges)
      if (id.empty()) throw std::invalid_argument("ScenarioConfig.mainline_edges has an empty edge id");
  } else if (!c.mainline_edges.empty() || !c.route_file.empty()) {
    throw std::invalid_argument(std::string("ScenarioConfig.") + (c.route_file.empty() ? "mainline_edges" : "route_file") +
                                " is only read with network_file (a road of the naming convention has its own)");
  } else if (c.generate_network) {
    validateRoadSpec(c.road);
  } else {  // a hand-written network: only what describes any road of the naming convention
    detail::refuseZoneStarts(c.road);
    detail::validateRoadZones(c.road);
    detail::validateRoadLanes(c.road);
  }
  requireInRange(c.penetration_rate, 0.0, 1.0, "penetration_rate");
  requirePositive(c.duration_s, "duration_s");
  requireInRange(c.mainline_flow_vphpl, 0.0, 1e6, "mainline_flow_vphpl");
  requireInRange(c.onramp_flow_vphpl, 0.0, 1e6, "onramp_flow_vphpl");
  validateSpeed(c.cav_speed, "cav_speed");
  validateSpeed(c.hdv_speed, "hdv_speed");
  validateInsertion(c.mainline_insertion, "mainline_insertion");
  validateInsertion(c.onramp_insertion, "onramp_insertion");
  requireFinite(c.max_depart_delay_s, "max_depart_delay_s");
  requireFinite(c.time_to_teleport_s, "time_to_teleport_s");
  requirePositive(c.step_length_s, "step_length_s");
  requirePositive(c.lateral_resolution_m, "lateral_resolution_m");
  if (c.netconvert_binary.empty())
    throw std::invalid_argument("ScenarioConfig.netconvert_binary is empty");
}

VTypeProbabilities vTypeProbabilities(const ScenarioConfig& c) {
  validateScenarioConfig(c);
  const double pr = c.penetration_rate;
  return {pr * c.cav_speed.p_fast, pr * (1.0 - c.cav_speed.p_fast),
          (1.0 - pr) * c.hdv_speed.p_fast, (1.0 - pr) * (1.0 - c.hdv_speed.p_fast)};
}

std::vector<RouteDemand> buildRoutes(const ScenarioConfig& c, const std::vector<EdgeInfo>& edges) {
  validateScenarioConfig(c);
  // RoadLayout needs the mainline lane count: take it from the first plain mainline edge.
  int lanes = 0;
  for (const EdgeInfo& e : edges)
    if (e.id.rfind("main_", 0) == 0 && e.id.find("_merge") == std::string::npos) {
      lanes = e.lane_count;
      break;
    }
  const RoadLayout road(edges, std::max(lanes, 1), c.road.cluster_length_m);
  const std::vector<EdgeInfo> main = orderedMainline(road, edges);
  // The network must be the road the config describes (RSUs get their zones from c.road).
  if (lanes != c.road.num_lanes)
    throw std::invalid_argument("network has " + std::to_string(lanes) +
                                " mainline lanes but road/num_lanes is " +
                                std::to_string(c.road.num_lanes));
  if (static_cast<int>(road.clusters().size()) != c.road.clusters)
    throw std::invalid_argument("network has " + std::to_string(road.clusters().size()) +
                                " clusters of road/cluster_length_m " +
                                num(c.road.cluster_length_m) + " m (mainline " +
                                num(road.mainlineLengthM()) + " m) but road/clusters is " +
                                std::to_string(c.road.clusters));
  const std::map<std::string, RouteShares> route_shares =
      c.route_shares.empty() ? defaultRouteShares(c.road.clusters) : c.route_shares;
  std::vector<std::string> known_sources{"main"};
  for (const ClusterInfo& k : road.clusters())
    if (!k.on_ramp_edge.empty()) known_sources.push_back("on" + std::to_string(k.index));
  for (const auto& entry : route_shares)
    if (std::find(known_sources.begin(), known_sources.end(), entry.first) == known_sources.end())
      throw std::invalid_argument("ScenarioConfig.route_shares: unknown source '" + entry.first + "'");

  const double x_end = main.back().x_end_m;
  std::vector<RouteDemand> routes;
  auto addSource = [&](const std::string& from, double x_from, const std::string& ramp,
                       double total_vph, int first_exit) {
    std::vector<std::string> destinations{"end"};
    for (const ClusterInfo& k : road.clusters())
      if (!k.off_ramp_edge.empty() && k.index >= first_exit) destinations.push_back("off" + std::to_string(k.index));
    const RouteShares& shares = checkedShares(route_shares, from, destinations);
    for (const std::string& to : destinations) {
      RouteDemand r;
      r.id = "r_" + from + "_" + to;
      r.from_ramp = !ramp.empty();
      if (r.from_ramp) r.edges.push_back(ramp);
      const ClusterInfo* exit = to == "end" ? nullptr : &road.clusters()[std::stoi(to.substr(3))];
      for (const std::string& id : mainlineBetween(main, x_from, exit ? exit->exit_x_m : x_end))
        r.edges.push_back(id);
      if (exit) r.edges.push_back(exit->off_ramp_edge);
      r.vehs_per_hour = total_vph * shareOf(shares, to);
      routes.push_back(r);
    }
  };
  addSource("main", main.front().x_start_m, "", c.mainline_flow_vphpl * road.numMainLanes(), 0);
  for (const ClusterInfo& k : road.clusters()) {
    if (k.on_ramp_edge.empty()) continue;
    addSource("on" + std::to_string(k.index), k.accel_lane_x_start_m, k.on_ramp_edge,
              c.onramp_flow_vphpl * road.edge(k.on_ramp_edge).lane_count, k.index + 1);
  }
  return routes;
}

}  // namespace palcas::sim

namespace palcas::sim {

OwnRoadOptions ownRoadOptions(const ScenarioConfig& c) {
  OwnRoadOptions o;
  o.mainline_edges = c.mainline_edges;
  o.clusters = c.road.clusters;
  o.zone_starts_m = c.road.zone_starts_m;
  o.zone_start_edges = c.road.zone_start_edges;
  return o;
}

std::vector<RouteDemand> buildOwnRoadRoutes(const ScenarioConfig& c, const OwnRoad& own) {
  validateScenarioConfig(c);
  if (own.num_main_lanes != c.road.num_lanes)
    throw std::invalid_argument("the network's mainline has " + std::to_string(own.num_main_lanes) +
                                " lanes (its widest edge) but road/num_lanes is " + std::to_string(c.road.num_lanes) +
                                ": set road/num_lanes to " + std::to_string(own.num_main_lanes));
  const RoadLayout road(own);
  const std::vector<std::string>& main = road.mainline();
  // Exits reachable from a place on the mainline: those leaving after it.
  auto exitsAfter = [&](double x_m) {
    std::vector<const ClusterInfo*> exits;
    for (const ClusterInfo& k : road.clusters())
      if (!k.off_ramp_edge.empty() && k.exit_x_m > x_m + X_TOLERANCE_M) exits.push_back(&k);
    return exits;
  };
  std::map<std::string, RouteShares> shares = c.route_shares;
  auto defaultShares = [](const std::vector<const ClusterInfo*>& exits, double to_exits) {
    RouteShares s;
    s["end"] = exits.empty() ? 1.0 : 1.0 - to_exits;
    for (const ClusterInfo* k : exits) s["off" + std::to_string(k->index)] = to_exits / exits.size();
    return s;
  };
  struct Source {
    std::string name, ramp, first_main;
    std::vector<const ClusterInfo*> exits;
    double vph;
  };
  std::vector<Source> sources;
  const EdgeInfo& first = road.edge(main.front());
  sources.push_back({"main", "", main.front(), exitsAfter(-1.0),
                     c.mainline_flow_vphpl * (first.lane_count - (first.has_accel_lane ? 1 : 0))});
  for (const ClusterInfo& k : road.clusters()) {
    if (k.on_ramp_edge.empty()) continue;
    sources.push_back({"on" + std::to_string(k.index), k.on_ramp_edge, k.on_ramp_joins_edge,
                       exitsAfter(k.accel_lane_x_start_m + k.accel_lane_length_m),
                       c.onramp_flow_vphpl * road.edge(k.on_ramp_edge).lane_count});
  }
  if (c.route_shares.empty())
    for (const Source& s : sources) shares[s.name] = defaultShares(s.exits, s.ramp.empty() ? 0.45 : 0.6);
  for (const auto& entry : shares)
    if (std::none_of(sources.begin(), sources.end(), [&](const Source& s) { return s.name == entry.first; }))
      throw std::invalid_argument("ScenarioConfig.route_shares: unknown source '" + entry.first + "'");
  std::vector<RouteDemand> routes;
  for (const Source& s : sources) {
    std::vector<std::string> destinations{"end"};
    for (const ClusterInfo* k : s.exits) destinations.push_back("off" + std::to_string(k->index));
    const RouteShares& mine = checkedShares(shares, s.name, destinations);
    const auto from = std::find(main.begin(), main.end(), s.first_main);
    for (std::size_t d = 0; d < destinations.size(); ++d) {
      RouteDemand r;
      r.id = "r_" + s.name + "_" + destinations[d];
      r.from_ramp = !s.ramp.empty();
      if (r.from_ramp) r.edges.push_back(s.ramp);
      const ClusterInfo* exit = d == 0 ? nullptr : s.exits[d - 1];
      const auto to = exit ? std::find(main.begin(), main.end(), exit->exit_from_edge) : main.end() - 1;
      r.edges.insert(r.edges.end(), from, to + 1);
      if (exit) r.edges.push_back(exit->off_ramp_edge);
      r.vehs_per_hour = s.vph * shareOf(mine, destinations[d]);
      routes.push_back(r);
    }
  }
  return routes;
}

}  // namespace palcas::sim
