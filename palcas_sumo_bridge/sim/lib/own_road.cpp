// A road the user brings: reading a .net.xml's topology and finding mainline, positions, ramps,
// acceleration lanes and zones in it. The rule: palcas_sim/own_road.h.
#include "palcas_sim/own_road.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <set>
#include <stdexcept>

#include "scenario_xml.h"

namespace palcas::sim {
namespace {

double toDouble(const std::string& s, const std::string& what) {
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used == s.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error("not a number: " + what + " = '" + s + "'");
}

int toLaneIndex(const std::string& s, const std::string& what) {
  const double v = toDouble(s, what);
  if (v < 0 || v != std::floor(v)) throw std::runtime_error("not a lane index: " + what + " = '" + s + "'");
  return static_cast<int>(v);
}

/// "edge_2" -> "edge" (SUMO lane ids are <edge>_<index>).
std::string edgeOfLane(const std::string& lane_id) {
  const std::size_t underscore = lane_id.rfind('_');
  return underscore == std::string::npos ? lane_id : lane_id.substr(0, underscore);
}

std::string joined(const std::vector<std::string>& ids) {
  std::string out;
  for (const std::string& id : ids) out += (out.empty() ? "" : ", ") + id;
  return out;
}

/// The network seen as edges and their lane connections.
class Graph {
 public:
  explicit Graph(const NetTopology& net) : net_(net) {
    for (const NetEdge& e : net.edges)
      if (!e.internal) edges_[e.id] = &e;
    for (const NetLink& l : net.links)
      if (edges_.count(l.from_edge) && edges_.count(l.to_edge)) road_links_.push_back(&l);
  }

  const NetEdge* find(const std::string& id) const {
    auto it = edges_.find(id);
    return it == edges_.end() ? nullptr : it->second;
  }
  const NetEdge& at(const std::string& id) const { return *edges_.at(id); }
  const std::map<std::string, const NetEdge*>& edges() const { return edges_; }

  /// Links between two road (non-internal) edges, U-turns left out (one carriageway).
  std::vector<const NetLink*> links(const std::string& from, const std::string& to) const {
    std::vector<const NetLink*> out;
    for (const NetLink* l : road_links_)
      if ((from.empty() || l->from_edge == from) && (to.empty() || l->to_edge == to) && !isUTurn(*l))
        out.push_back(l);
    return out;
  }
  std::vector<std::string> successors(const std::string& id) const {
    std::set<std::string> s;
    for (const NetLink* l : links(id, "")) s.insert(l->to_edge);
    return {s.begin(), s.end()};
  }
  bool hasPredecessor(const std::string& id) const { return !links("", id).empty(); }

  /// Length of the junction-internal lanes from `via` to the next road edge; `visit` is
  /// called with each internal edge and the distance driven before it.
  template <typename Visit>
  double viaLength(const std::string& via, Visit visit) const {
    double total = 0.0;
    std::string lane = via;
    for (int guard = 0; !lane.empty() && guard < 16; ++guard) {
      visit(edgeOfLane(lane), total);
      auto it = net_.lane_length_m.find(lane);
      total += it == net_.lane_length_m.end() ? 0.0 : it->second;
      std::string next;
      for (const NetLink& l : net_.links)
        if (l.from_edge + "_" + std::to_string(l.from_lane) == lane && !l.via.empty()) next = l.via;
      lane = next;
    }
    return total;
  }

 private:
  bool isUTurn(const NetLink& l) const {
    return edges_.at(l.from_edge)->from_node == edges_.at(l.to_edge)->to_node;
  }
  const NetTopology& net_;
  std::map<std::string, const NetEdge*> edges_;
  std::vector<const NetLink*> road_links_;
};

std::vector<std::string> givenMainline(const Graph& g, const std::vector<std::string>& ids) {
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!g.find(ids[i]))
      throw std::invalid_argument("mainline_edges: the network has no edge '" + ids[i] + "'");
    if (i > 0 && g.links(ids[i - 1], ids[i]).empty())
      throw std::invalid_argument("mainline_edges: no lane of '" + ids[i - 1] + "' connects to '" +
                                  ids[i] + "'");
    if (std::count(ids.begin(), ids.end(), ids[i]) > 1)
      throw std::invalid_argument("mainline_edges: '" + ids[i] + "' is listed twice");
  }
  return ids;
}

/// The rule of own_road.h: the widest source edge, then the widest successor each time.
std::vector<std::string> foundMainline(const Graph& g) {
  std::vector<std::string> widest;
  int most = 0;
  for (const auto& [id, e] : g.edges()) {
    if (g.hasPredecessor(id)) continue;
    if (e->lane_count < most) continue;
    if (e->lane_count > most) widest.clear();
    widest.push_back(id);
    most = e->lane_count;
  }
  if (widest.empty())
    throw std::invalid_argument("no mainline found: every edge has a predecessor (a loop?); "
                                "list the mainline in mainline_edges");
  if (widest.size() > 1)
    throw std::invalid_argument("no mainline found: " + std::to_string(widest.size()) +
                                " source edges have " + std::to_string(most) + " lanes (" +
                                joined(widest) + "); list the mainline in mainline_edges");
  std::vector<std::string> main{widest.front()};
  std::set<std::string> seen{main.front()};
  while (true) {
    const std::string& here = main.back();
    std::vector<std::string> best;
    int best_lanes = -1, best_links = -1;
    for (const std::string& next : g.successors(here)) {
      if (seen.count(next)) continue;
      const int lanes = g.at(next).lane_count;
      const int links = static_cast<int>(g.links(here, next).size());
      if (lanes > best_lanes || (lanes == best_lanes && links > best_links)) {
        best = {next};
        best_lanes = lanes;
        best_links = links;
      } else if (lanes == best_lanes && links == best_links) {
        best.push_back(next);
      }
    }
    if (best.empty()) break;
    if (best.size() > 1)
      throw std::invalid_argument("no mainline found: after '" + here + "' the road splits into " +
                                  joined(best) + " with equal lanes; list the mainline in mainline_edges");
    main.push_back(best.front());
    seen.insert(best.front());
  }
  return main;
}

}  // namespace

NetTopology readNetTopology(const std::string& net_file) {
  const std::string text = xml::stripComments(xml::readFile(net_file));
  if (xml::findTags(text, "net").empty())
    throw std::runtime_error("'" + net_file + "' is not a SUMO network (no <net> element)");
  NetTopology net;
  const std::vector<xml::Tag> edges = xml::findTags(text, "edge");
  const std::vector<xml::Tag> lanes = xml::findTags(text, "lane");
  std::size_t lane_at = 0;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::size_t end = i + 1 < edges.size() ? edges[i + 1].offset : text.size();
    NetEdge e;
    e.id = xml::attribute(edges[i], "id");
    e.from_node = xml::attribute(edges[i], "from");
    e.to_node = xml::attribute(edges[i], "to");
    e.internal = xml::attribute(edges[i], "function") == "internal";
    for (; lane_at < lanes.size() && lanes[lane_at].offset < end; ++lane_at) {
      if (lanes[lane_at].offset < edges[i].offset) continue;
      const std::string lane_id = xml::attribute(lanes[lane_at], "id");
      const double length = toDouble(xml::attribute(lanes[lane_at], "length"),
                                     "length of lane '" + lane_id + "' in " + net_file);
      net.lane_length_m[lane_id] = length;
      if (e.lane_count == 0) e.length_m = length;
      ++e.lane_count;
    }
    if (e.id.empty() || e.lane_count == 0)
      throw std::runtime_error("edge without id or lanes in '" + net_file + "'");
    if (xml::attribute(edges[i], "function").empty() || e.internal) net.edges.push_back(e);
  }
  for (const xml::Tag& tag : xml::findTags(text, "connection")) {
    const std::string what = "connection from '" + xml::attribute(tag, "from") + "' in " + net_file;
    net.links.push_back({xml::attribute(tag, "from"), toLaneIndex(xml::attribute(tag, "fromLane"), what),
                         xml::attribute(tag, "to"), toLaneIndex(xml::attribute(tag, "toLane"), what),
                         xml::attribute(tag, "via")});
  }
  return net;
}

namespace {

std::string metres(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

/// Where each zone starts along a mainline of `length_m`: equal parts, or the user's x or edges.
std::vector<double> zoneStarts(const OwnRoadOptions& o, const std::vector<std::string>& mainline,
                               std::map<std::string, EdgeInfo>& info, double length_m) {
  std::vector<double> starts;
  if (!o.zone_starts_m.empty() && !o.zone_start_edges.empty())
    throw std::invalid_argument("road/zone_starts_m and road/zone_start_edges both given: say where the zones "
                                "start one way");
  const std::size_t given = o.zone_starts_m.empty() ? o.zone_start_edges.size() : o.zone_starts_m.size();
  if (given == 0) {
    for (int k = 0; k < o.clusters; ++k) starts.push_back(k * length_m / o.clusters);
    return starts;
  }
  const std::string key = o.zone_starts_m.empty() ? "road/zone_start_edges" : "road/zone_starts_m";
  if (given != static_cast<std::size_t>(o.clusters))
    throw std::invalid_argument(key + " lists " + std::to_string(given) + " zones but road/clusters is " +
                                std::to_string(o.clusters) + ": set road/clusters to " + std::to_string(given));
  for (std::size_t k = 0; k < given; ++k) {
    const std::string at = key + "[" + std::to_string(k) + "]";
    double x = 0.0;
    if (o.zone_starts_m.empty()) {
      const std::string& id = o.zone_start_edges[k];
      if (std::find(mainline.begin(), mainline.end(), id) == mainline.end())
        throw std::invalid_argument(at + " '" + id + "' is not a mainline edge (the mainline: " + joined(mainline) +
                                    ")");
      x = info[id].x_start_m;
      if (k == 0 && id != mainline.front())
        throw std::invalid_argument(at + " '" + id + "': zone 0 starts where the mainline does, at '" +
                                    mainline.front() + "'");
    } else {
      x = o.zone_starts_m[k];
      if (k == 0 && x != 0.0)
        throw std::invalid_argument(at + " = " + metres(x) + " m: zone 0 starts where the mainline does, at 0");
    }
    if (k > 0 && !(x > starts.back()))
      throw std::invalid_argument(at + " starts at " + metres(x) + " m, not after the zone before it (" +
                                  metres(starts.back()) + " m): zones are listed in driving order");
    if (!(x < length_m))
      throw std::invalid_argument(at + " starts at " + metres(x) + " m, past the mainline's end (" +
                                  metres(length_m) + " m)");
    starts.push_back(x);
  }
  return starts;
}

}  // namespace

OwnRoad discoverOwnRoad(const NetTopology& net, const OwnRoadOptions& options) {
  if (options.clusters < 1)
    throw std::invalid_argument("road/clusters must be >= 1, got " + std::to_string(options.clusters));
  const Graph g(net);
  if (g.edges().empty()) throw std::invalid_argument("the network has no edges");
  OwnRoad road;
  road.clusters = options.clusters;
  road.mainline = options.mainline_edges.empty() ? foundMainline(g) : givenMainline(g, options.mainline_edges);
  const std::set<std::string> on_main(road.mainline.begin(), road.mainline.end());

  // Positions: cumulative lane length, junction-internal lanes included.
  std::map<std::string, EdgeInfo> info;
  double x = 0.0;
  for (std::size_t i = 0; i < road.mainline.size(); ++i) {
    const NetEdge& e = g.at(road.mainline[i]);
    if (i > 0) {
      const std::string& before = road.mainline[i - 1];
      const auto links = g.links(before, e.id);
      const std::string via = links.empty() ? "" : links.front()->via;
      x += g.viaLength(via, [&](const std::string&, double) {});
    }
    EdgeInfo& m = info[e.id];
    m.id = e.id;
    m.part = RoadPart::kMainline;
    m.lane_count = e.lane_count;
    m.x_start_m = x;
    x += e.length_m;
    m.x_end_m = x;
  }
  road.mainline_length_m = x;
  if (!(x > 0.0)) throw std::invalid_argument("the mainline (" + joined(road.mainline) + ") has length 0");
  road.cluster_length_m = x / options.clusters;
  road.zone_starts_m = zoneStarts(options, road.mainline, info, x);
  const auto zoneOf = [&](double at_m) {
    const auto after = std::upper_bound(road.zone_starts_m.begin(), road.zone_starts_m.end(), at_m);
    return std::max(0, static_cast<int>(after - road.zone_starts_m.begin()) - 1);
  };
  // Every junction-internal lane leaving a mainline edge starts where that edge ends.
  for (const std::string& id : road.mainline)
    for (const NetLink* l : g.links(id, ""))
      g.viaLength(l->via, [&](const std::string& internal, double driven) {
        road.internal_x_start_m.emplace(internal, info[id].x_end_m + driven);
      });

  // Acceleration lanes: lane 0 fed by ramps or an acceleration lane, by no through lane.
  for (std::size_t i = 1; i < road.mainline.size(); ++i) {
    EdgeInfo& here = info[road.mainline[i]];
    const EdgeInfo& before = info[road.mainline[i - 1]];
    bool fed_by_through_lane = false, fed_otherwise = false;
    for (const NetLink* l : g.links("", here.id)) {
      if (l->to_lane != 0) continue;
      const bool through = l->from_edge == before.id && !(before.has_accel_lane && l->from_lane == 0);
      (through ? fed_by_through_lane : fed_otherwise) = true;
    }
    here.has_accel_lane = here.lane_count >= 2 && fed_otherwise && !fed_by_through_lane;
  }
  for (const auto& [id, e] : info)
    road.num_main_lanes = std::max(road.num_main_lanes, e.lane_count - (e.has_accel_lane ? 1 : 0));

  // Ramps and their zones.
  std::map<int, std::string> on_ramp_of_zone, off_ramp_of_zone;
  for (const auto& [id, edge] : g.edges()) {
    if (on_main.count(id)) continue;
    EdgeInfo r;
    r.id = id;
    r.lane_count = edge->lane_count;
    const auto into = [&] {
      for (const NetLink* l : g.links(id, ""))
        if (on_main.count(l->to_edge)) return l;
      return static_cast<const NetLink*>(nullptr);
    }();
    const auto out_of = [&] {
      for (const NetLink* l : g.links("", id))
        if (on_main.count(l->from_edge)) return l;
      return static_cast<const NetLink*>(nullptr);
    }();
    if (into && out_of)
      throw std::invalid_argument("edge '" + id + "' both leaves and joins the mainline; list the mainline in "
                                  "mainline_edges if it is part of it");
    if (into) {
      const double join_m = info[into->to_edge].x_start_m;
      const double via_m = g.viaLength(into->via, [](const std::string&, double) {});
      g.viaLength(into->via, [&](const std::string& internal, double driven) {
        road.internal_x_start_m.emplace(internal, join_m - via_m + driven);
      });
      r.part = RoadPart::kOnRamp;
      r.x_end_m = join_m - via_m;
      r.x_start_m = r.x_end_m - edge->length_m;
      r.cluster = zoneOf(join_m);
      auto [it, fresh] = on_ramp_of_zone.emplace(r.cluster, id);
      if (!fresh)
        throw std::invalid_argument("zone " + std::to_string(r.cluster) + " has two on-ramps ('" + it->second +
                                    "' and '" + id + "'): one per zone is supported; change road/clusters or say where the zones start (road/zone_starts_m)");
      road.on_ramp_joins_edge[r.cluster] = into->to_edge;
      // The acceleration lane it feeds belongs to its zone, over every edge it spans.
      for (auto m = std::find(road.mainline.begin(), road.mainline.end(), into->to_edge);
           m != road.mainline.end() && info[*m].has_accel_lane; ++m)
        info[*m].cluster = r.cluster;
    } else if (out_of) {
      const EdgeInfo& from = info[out_of->from_edge];
      const int rightmost_through = from.has_accel_lane ? 1 : 0;
      for (const NetLink* l : g.links(from.id, id))
        if (l->from_lane != rightmost_through)
          throw std::invalid_argument("off-ramp '" + id + "' leaves from SUMO lane " + std::to_string(l->from_lane) +
                                      " of '" + from.id + "': only an exit from the rightmost through lane (" +
                                      std::to_string(rightmost_through) + ") is supported");
      r.part = RoadPart::kOffRamp;
      // It starts after its junction lane (x runs on through it from the mainline's end).
      r.x_start_m = from.x_end_m + g.viaLength(out_of->via, [](const std::string&, double) {});
      r.x_end_m = r.x_start_m + edge->length_m;
      // An exit at a zone boundary belongs to the zone its traffic approaches it in.
      r.cluster = zoneOf(from.x_end_m - 1e-6);
      auto [it, fresh] = off_ramp_of_zone.emplace(r.cluster, id);
      if (!fresh)
        throw std::invalid_argument("zone " + std::to_string(r.cluster) + " has two off-ramps ('" + it->second +
                                    "' and '" + id + "'): one per zone is supported; change road/clusters or say where the zones start (road/zone_starts_m)");
      road.exit_from_edge[r.cluster] = from.id;
    }
    road.edges.push_back(r);
  }
  // Junction lanes from the mainline onto each off-ramp: the internal edges on those links'
  // way, less any that a link to somewhere else also drives through.
  std::map<std::string, std::set<std::string>> onto;  // internal edge -> off-ramps it leads onto
  std::set<std::string> shared;                        // on the way of a link to anywhere else
  for (const std::string& id : road.mainline)
    for (const NetLink* l : g.links(id, "")) {
      const bool to_off_ramp = !on_main.count(l->to_edge) &&
                               std::any_of(road.edges.begin(), road.edges.end(), [&](const EdgeInfo& e) {
                                 return e.id == l->to_edge && e.part == RoadPart::kOffRamp;
                               });
      g.viaLength(l->via, [&](const std::string& internal, double) {
        if (to_off_ramp) onto[internal].insert(l->to_edge);
        else shared.insert(internal);
      });
    }
  for (const auto& [internal, ramps] : onto)
    if (ramps.size() == 1 && !shared.count(internal)) road.onto_off_ramp[internal] = *ramps.begin();
  for (const std::string& id : road.mainline) {
    EdgeInfo& m = info[id];
    if (m.has_accel_lane && m.cluster < 0)
      throw std::invalid_argument("mainline edge '" + id + "': its lane 0 is fed by no through lane and by no on-ramp");
    road.edges.push_back(m);
  }
  return road;
}

}  // namespace palcas::sim
