#include "palcas_sim/road_layout.h"

#include "palcas_sim/own_road.h"

#include <algorithm>
#include <iterator>
#include <cmath>
#include <stdexcept>

namespace palcas::sim {
namespace {

bool startsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

/// Cluster index in names like "on_2" or "main_1_merge"; -1 when there is none.
int clusterIndexOf(const std::string& id, const std::string& prefix) {
  const std::size_t begin = prefix.size();
  std::size_t end = begin;
  while (end < id.size() && std::isdigit(static_cast<unsigned char>(id[end]))) ++end;
  if (end == begin) return -1;
  return std::stoi(id.substr(begin, end - begin));
}

}  // namespace

RoadLayout::RoadLayout(std::vector<EdgeInfo> edges, int num_main_lanes, double cluster_length_m)
    : edges_(std::move(edges)), num_main_lanes_(num_main_lanes), cluster_length_m_(cluster_length_m) {
  if (!(cluster_length_m_ > 0.0))
    throw std::invalid_argument("RoadLayout: cluster length must be > 0, got " +
                                std::to_string(cluster_length_m_));
  if (num_main_lanes_ < 1)
    throw std::invalid_argument("RoadLayout: need at least one mainline lane");
  for (std::size_t i = 0; i < edges_.size(); ++i) {
    EdgeInfo& e = edges_[i];
    if (startsWith(e.id, "main_")) {
      e.part = RoadPart::kMainline;
      e.has_accel_lane = e.id.size() > 6 && e.id.rfind("_merge") == e.id.size() - 6;
      e.cluster = e.has_accel_lane ? clusterIndexOf(e.id, "main_") : -1;
      if (e.has_accel_lane && e.cluster < 0)
        throw std::invalid_argument("RoadLayout: merge edge '" + e.id + "' has no cluster index");
      mainline_length_m_ = std::max(mainline_length_m_, e.x_end_m);
    } else if (startsWith(e.id, "on_")) {
      e.part = RoadPart::kOnRamp;
      e.cluster = clusterIndexOf(e.id, "on_");
    } else if (startsWith(e.id, "off_")) {
      e.part = RoadPart::kOffRamp;
      e.cluster = clusterIndexOf(e.id, "off_");
    }
    index_[e.id] = i;
  }
  const int cluster_count = std::max(1, static_cast<int>(std::ceil(mainline_length_m_ / cluster_length_m_ - 1e-9)));
  std::vector<const EdgeInfo*> main;
  for (const EdgeInfo& e : edges_)
    if (e.part == RoadPart::kMainline) main.push_back(&e);
  std::sort(main.begin(), main.end(), [](const EdgeInfo* a, const EdgeInfo* b) { return a->x_start_m < b->x_start_m; });
  for (const EdgeInfo* e : main) mainline_.push_back(e->id);
  std::vector<double> starts;
  for (int k = 0; k < cluster_count; ++k) starts.push_back(k * cluster_length_m_);
  buildClusters(starts);
  for (const ClusterInfo& c : clusters_)
    if (!c.on_ramp_edge.empty() && c.merge_edge.empty())
      throw std::invalid_argument("RoadLayout: cluster " + std::to_string(c.index) +
                                  " has on-ramp '" + c.on_ramp_edge + "' but no merge edge");
}

RoadLayout::RoadLayout(const OwnRoad& road)
    : edges_(road.edges), mainline_(road.mainline), internal_x_start_m_(road.internal_x_start_m),
      onto_off_ramp_(road.onto_off_ramp), measured_along_lanes_(true), num_main_lanes_(road.num_main_lanes),
      cluster_length_m_(road.cluster_length_m), mainline_length_m_(road.mainline_length_m) {
  if (mainline_.empty() || !(cluster_length_m_ > 0.0) || num_main_lanes_ < 1)
    throw std::invalid_argument("RoadLayout: the road has no mainline");
  for (std::size_t i = 0; i < edges_.size(); ++i) index_[edges_[i].id] = i;
  if (static_cast<int>(road.zone_starts_m.size()) != road.clusters)
    throw std::invalid_argument("RoadLayout: the road has " + std::to_string(road.clusters) + " zones but " +
                                std::to_string(road.zone_starts_m.size()) + " zone starts");
  buildClusters(road.zone_starts_m);
  for (const auto& [zone, edge_id] : road.exit_from_edge) {
    // The exit is where the mainline edge it leaves from ends (its ramp starts after the
    // junction lane).
    clusters_[zone].exit_from_edge = edge_id;
    clusters_[zone].exit_x_m = edge(edge_id).x_end_m;
  }
  for (const auto& [zone, edge_id] : road.on_ramp_joins_edge) {
    ClusterInfo& c = clusters_[zone];
    c.on_ramp_joins_edge = edge_id;
    // An on-ramp without an acceleration lane: its traffic joins where that edge starts.
    if (c.merge_edge.empty()) c.accel_lane_x_start_m = edge(edge_id).x_start_m;
  }
}

void RoadLayout::buildClusters(const std::vector<double>& zone_starts_m) {
  const int cluster_count = static_cast<int>(zone_starts_m.size());
  clusters_.resize(cluster_count);
  for (int k = 0; k < cluster_count; ++k) {
    clusters_[k].index = k;
    clusters_[k].x_start_m = zone_starts_m[k];
    clusters_[k].x_end_m = k + 1 < cluster_count ? zone_starts_m[k + 1]
                           : measured_along_lanes_ ? mainline_length_m_
                                                   : std::min((k + 1) * cluster_length_m_, mainline_length_m_);
  }
  for (const EdgeInfo& e : edges_) {
    if (e.cluster < 0) continue;
    if (e.cluster >= cluster_count)
      throw std::invalid_argument("RoadLayout: edge '" + e.id + "' names cluster " +
                                  std::to_string(e.cluster) + " but the mainline has only " +
                                  std::to_string(cluster_count));
    ClusterInfo& c = clusters_[e.cluster];
    if (e.part == RoadPart::kOnRamp) c.on_ramp_edge = e.id;
    if (e.part == RoadPart::kOffRamp) {
      c.off_ramp_edge = e.id;
      c.exit_x_m = e.x_start_m;
    }
    if (e.has_accel_lane) {
      // An acceleration lane over several edges (own roads): from its first edge to its last.
      if (c.merge_edge.empty() || e.x_start_m < c.accel_lane_x_start_m) {
        const double end_m = c.merge_edge.empty() ? e.x_end_m : c.accel_lane_x_start_m + c.accel_lane_length_m;
        c.merge_edge = e.id;
        c.accel_lane_x_start_m = e.x_start_m;
        c.accel_lane_length_m = end_m - e.x_start_m;
      } else {
        c.accel_lane_length_m = std::max(c.accel_lane_length_m, e.x_end_m - c.accel_lane_x_start_m);
      }
    }
  }
}

double RoadLayout::xAlongMainline(const std::string& edge_id, double lane_pos_m, double otherwise) const {
  auto it = index_.find(edge_id);
  if (it != index_.end()) {
    const EdgeInfo& e = edges_[it->second];
    return e.part == RoadPart::kUnknown ? otherwise : e.x_start_m + lane_pos_m;
  }
  auto internal = internal_x_start_m_.find(edge_id);
  return internal == internal_x_start_m_.end() ? otherwise : internal->second + lane_pos_m;
}

std::map<std::string, int> RoadLayout::offRampEdges() const {
  std::map<std::string, int> out;
  for (const ClusterInfo& c : clusters_)
    if (!c.off_ramp_edge.empty()) out[c.off_ramp_edge] = c.index;
  for (const auto& [internal, ramp] : onto_off_ramp_) {
    auto it = out.find(ramp);
    if (it != out.end()) out[internal] = it->second;
  }
  return out;
}

const EdgeInfo& RoadLayout::edge(const std::string& id) const {
  auto it = index_.find(id);
  if (it == index_.end()) throw std::out_of_range("RoadLayout: unknown edge '" + id + "'");
  return edges_[it->second];
}

int RoadLayout::clusterAt(double x_m) const {
  const auto after = std::upper_bound(clusters_.begin(), clusters_.end(), x_m,
                                      [](double x, const ClusterInfo& c) { return x < c.x_start_m; });
  return std::max(0, static_cast<int>(after - clusters_.begin()) - 1);
}

int RoadLayout::zoneAt(double x_m) const {
  if (clusters_.empty() || !(x_m >= clusters_.front().x_start_m) || !(x_m < clusters_.back().x_end_m)) return -1;
  // The zones follow each other along x: the last one starting at or before x.
  const auto after = std::upper_bound(clusters_.begin(), clusters_.end(), x_m,
                                      [](double x, const ClusterInfo& c) { return x < c.x_start_m; });
  const ClusterInfo& c = *std::prev(after);
  return x_m < c.x_end_m ? c.index : -1;
}

int RoadLayout::paperLane(const std::string& edge_id, int sumo_lane_index) const {
  const EdgeInfo& e = edge(edge_id);
  if (e.part != RoadPart::kMainline || sumo_lane_index < 0 || sumo_lane_index >= e.lane_count)
    return 0;
  if (e.has_accel_lane) return sumo_lane_index;  // SUMO lane 0 is the acceleration lane (0)
  return sumo_lane_index + 1;
}

int RoadLayout::sumoLaneIndex(const std::string& edge_id, int paper_lane) const {
  const EdgeInfo& e = edge(edge_id);
  if (e.part != RoadPart::kMainline || paper_lane < 1 || paper_lane > num_main_lanes_) return -1;
  const int index = e.has_accel_lane ? paper_lane : paper_lane - 1;
  return index < e.lane_count ? index : -1;
}

int RoadLayout::mainLanesOn(const std::string& edge_id) const {
  if (!hasEdge(edge_id) || edge(edge_id).part != RoadPart::kMainline) return num_main_lanes_;
  int lanes = 0;
  while (lanes < num_main_lanes_ && sumoLaneIndex(edge_id, lanes + 1) >= 0) ++lanes;
  return std::max(lanes, 1);
}

void classifyRouteByEdges(const RoadLayout& road, const std::vector<std::string>& edges, RouteKind* kind,
                          int* entry_cluster, int* exit_cluster) {
  int entry = -1, exit = -1;
  for (const std::string& id : edges) {
    if (!road.hasEdge(id)) continue;
    const EdgeInfo& e = road.edge(id);
    if (e.part == RoadPart::kOnRamp && entry < 0) entry = e.cluster;
    if (e.part == RoadPart::kOffRamp && exit < 0) exit = e.cluster;
  }
  *entry_cluster = entry;
  *exit_cluster = exit;
  if (entry < 0) *kind = exit < 0 ? RouteKind::kMainThrough : RouteKind::kMainExit;
  else *kind = exit < 0 ? RouteKind::kRampThrough : RouteKind::kRampExit;
}

}  // namespace palcas::sim
