// Compiled twice: as is against libsumo (SUMO in-process), and with LIBTRACI defined
// against libtraci (a client of an external sumo / sumo-gui). LIBSUMO_NAMESPACE names the
// API namespace in both cases; the result types stay in namespace libsumo.
#ifdef PALCAS_USE_LIBTRACI
#include <libsumo/libtraci.h>
#else
#include <libsumo/libsumo.h>
#endif

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include "palcas_sim/sumo_session.h"

namespace palcas::sim {
namespace api = LIBSUMO_NAMESPACE;

namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// Every variable SUMO builds for every vehicle every step costs time, so the list is short:
// the lane id carries edge and lane index, and the heading (only for drawing) comes from
// successive positions.
const std::vector<int>& vehicleVariables() {
  static const std::vector<int> vars = {
      libsumo::VAR_POSITION,  libsumo::VAR_SPEED,        libsumo::VAR_ACCELERATION,
      libsumo::VAR_SPEED_LAT, libsumo::VAR_LANE_ID,      libsumo::VAR_LANEPOSITION,
      libsumo::VAR_LANEPOSITION_LAT};
  return vars;
}

/// "<edge>_<index>" (internal lanes ":<junction>_<n>_<index>") into edge and index.
void splitLaneId(const std::string& lane_id, std::string* edge, int* index) {
  const std::size_t cut = lane_id.rfind('_');
  if (cut == std::string::npos) {
    *edge = lane_id;
    *index = -1;
    return;
  }
  *edge = lane_id.substr(0, cut);
  *index = std::atoi(lane_id.c_str() + cut + 1);
}

double asDouble(const libsumo::TraCIResults& r, int var) {
  auto it = r.find(var);
  if (it == r.end()) return std::numeric_limits<double>::quiet_NaN();
  if (auto d = std::dynamic_pointer_cast<libsumo::TraCIDouble>(it->second)) return d->value;
  if (auto i = std::dynamic_pointer_cast<libsumo::TraCIInt>(it->second)) return i->value;
  return std::numeric_limits<double>::quiet_NaN();
}

std::string asString(const libsumo::TraCIResults& r, int var) {
  auto it = r.find(var);
  if (it == r.end()) return {};
  if (auto s = std::dynamic_pointer_cast<libsumo::TraCIString>(it->second)) return s->value;
  return {};
}

std::vector<std::string> asStringList(const libsumo::TraCIResults& r, int var) {
  auto it = r.find(var);
  if (it == r.end()) return {};
  if (auto s = std::dynamic_pointer_cast<libsumo::TraCIStringList>(it->second)) return s->value;
  return {};
}

int clusterSuffix(const std::string& s, const std::string& prefix) {
  if (s.compare(0, prefix.size(), prefix) != 0 || s.size() == prefix.size()) return -2;
  for (std::size_t i = prefix.size(); i < s.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(s[i]))) return -2;
  return std::stoi(s.substr(prefix.size()));
}

/// PALCAS_TRACE_SUMO=1: every lane-change and route command on stderr (for SUMO bugs).
bool traceCommands() {
  static const bool on = std::getenv("PALCAS_TRACE_SUMO") != nullptr;
  return on;
}

}  // namespace

void parseRouteId(const std::string& route_id, RouteKind* kind, int* entry_cluster,
                  int* exit_cluster) {
  const std::size_t first = route_id.find('_');
  const std::size_t second = route_id.find('_', first + 1);
  if (route_id.compare(0, 2, "r_") != 0 || second == std::string::npos)
    throw std::invalid_argument("route id '" + route_id + "' is not of the form r_<from>_<to>");
  const std::string from = route_id.substr(first + 1, second - first - 1);
  const std::string to = route_id.substr(second + 1);
  const int entry = from == "main" ? -1 : clusterSuffix(from, "on");
  const int exit = to == "end" ? -1 : clusterSuffix(to, "off");
  if (entry == -2 || exit == -2)
    throw std::invalid_argument("route id '" + route_id +
                                "': origin must be main|on<k> and destination end|off<k>");
  *entry_cluster = entry;
  *exit_cluster = exit;
  if (entry < 0) *kind = exit < 0 ? RouteKind::kMainThrough : RouteKind::kMainExit;
  else *kind = exit < 0 ? RouteKind::kRampThrough : RouteKind::kRampExit;
}

const char* SumoSession::apiName() {
#ifdef PALCAS_USE_LIBTRACI
  return "libtraci";
#else
  return "libsumo";
#endif
}

SumoSession::SumoSession(const SessionOptions& options) : options_(options) {
  std::vector<std::string> cmd{options_.sumo_binary};
#ifndef PALCAS_USE_LIBTRACI
  cmd[0] = "sumo";  // in-process: the binary name is only argv[0]
#endif
  cmd.insert(cmd.end(), options_.sumo_args.begin(), options_.sumo_args.end());
  // SUMO only reports collisions; step() removes the colliding vehicles (remove_collided).
  if (options_.remove_collided) cmd.insert(cmd.end(), {"--collision.action", "warn"});
  try {
#ifdef PALCAS_USE_LIBTRACI
    api::Simulation::start(cmd, options_.traci_port);
#else
    api::Simulation::load(std::vector<std::string>(cmd.begin() + 1, cmd.end()));
#endif
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("SUMO did not start (") + apiName() + "): " + e.what());
  }
  open_ = true;
  step_length_s_ = api::Simulation::getDeltaT();
  time_s_ = api::Simulation::getTime();
  const std::vector<int> sim_vars{
      libsumo::VAR_DEPARTED_VEHICLES_IDS, libsumo::VAR_ARRIVED_VEHICLES_IDS,
      libsumo::VAR_COLLIDING_VEHICLES_IDS, libsumo::VAR_TELEPORT_STARTING_VEHICLES_IDS,
      libsumo::VAR_LOADED_VEHICLES_NUMBER};
  api::Simulation::subscribe(sim_vars);
  readNetwork();
}

SumoSession::~SumoSession() {
  if (!open_) return;
  try {
    api::Simulation::close();
  } catch (...) {
    // Closing a simulation that already ended must not throw from a destructor.
  }
}

void SumoSession::readNetwork() {
  std::vector<EdgeInfo> edges;
  int main_lanes = 0;
  for (const std::string& id : api::Edge::getIDList()) {
    if (id.empty() || id[0] == ':') continue;  // junction-internal edges
    EdgeInfo e;
    e.id = id;
    e.lane_count = api::Edge::getLaneNumber(id);
    const auto shape = api::Lane::getShape(id + "_" + std::to_string(e.lane_count - 1)).value;
    e.x_start_m = shape.front().x;
    e.x_end_m = shape.back().x;
    edges.push_back(e);
    for (int lane = 0; lane < e.lane_count; ++lane) {
      std::vector<std::pair<double, double>> line;
      for (const auto& p : api::Lane::getShape(id + "_" + std::to_string(lane)).value)
        line.emplace_back(p.x, p.y);
      lane_shapes_.push_back(std::move(line));
    }
    if (id.compare(0, 5, "main_") == 0 && id.find("_merge") == std::string::npos)
      main_lanes = std::max(main_lanes, e.lane_count);
  }
  road_ = std::make_unique<RoadLayout>(edges, main_lanes, options_.cluster_length_m);
  double end_x = -INF, start_x = INF;
  for (const EdgeInfo& e : edges) {
    if (e.id.compare(0, 5, "main_") != 0) continue;
    if (e.x_end_m > end_x) {
      end_x = e.x_end_m;
      end_edge_ = e.id;
    }
    if (e.x_start_m < start_x) {
      start_x = e.x_start_m;
      insertion_edge_ = e.id;
    }
  }
  // The mainline edge feeding an off-ramp: the one whose end is where the ramp starts.
  for (const ClusterInfo& c : road_->clusters()) {
    if (c.off_ramp_edge.empty()) continue;
    for (const EdgeInfo& e : edges)
      if (e.id.compare(0, 5, "main_") == 0 && std::abs(e.x_end_m - c.exit_x_m) < 1.0)
        pre_exit_edge_[c.index] = e.id;
  }
  for (const EdgeInfo& e : edges)
    if (e.id.compare(0, 5, "main_") == 0 && !e.has_accel_lane) {
      lane_width_m_ = api::Lane::getWidth(e.id + "_0");
      break;
    }
  // Mainline edges whose successor has another lane count (into or out of a merge edge):
  // a SUMO lane index means another lane there.
  for (const EdgeInfo& e : edges)
    for (const EdgeInfo& f : edges)
      if (e.id.compare(0, 5, "main_") == 0 && f.id.compare(0, 5, "main_") == 0 &&
          std::abs(f.x_start_m - e.x_end_m) < 1.0 && f.lane_count != e.lane_count)
        index_shift_ahead_.insert(e.id);
}

int SumoSession::minExpectedVehicles() const { return api::Simulation::getMinExpectedNumber(); }

std::uint64_t SumoSession::insertionDropped() const {
  // SUMO 1.15 has no count of its own (MSVehicleControl's discarded count is not in the
  // API): every vehicle it built from a flow (loaded) either departed, still waits in the
  // insertion queue (pending), or was dropped after waiting max-depart-delay.
  const std::uint64_t waiting = api::Simulation::getPendingVehicles().size();
  const std::uint64_t accounted = departed_vehicles_ + waiting;
  return loaded_vehicles_ > accounted ? loaded_vehicles_ - accounted : 0;
}

std::string SumoSession::sumoVersion() const { return api::Simulation::getVersion().second; }

const VehicleRecord* SumoSession::find(const std::string& id) const {
  auto it = index_.find(id);
  return it == index_.end() ? nullptr : &vehicles_[it->second];
}

const StepEvents& SumoSession::step() {
  std::vector<std::string> vanished;
  for (VehicleRecord& v : vehicles_) {
    try {
      applyHeldCommand(v);
    } catch (const libsumo::TraCIException& e) {
      // SUMO no longer knows it (removed without a report we read): forget it instead of
      // ending the simulation. Counted; the reason goes to stderr once per vehicle.
      std::fprintf(stderr, "[palcas sumo t=%.1f] %s vanished from SUMO (edge %s, x %.1f): %s\n",
                   time_s_, v.id.c_str(), v.edge.c_str(), v.x_m, e.what());
      vanished.push_back(v.id);
    }
  }
  for (const std::string& id : vanished) removeVehicle(id, nullptr);
  vanished_vehicles_ += vanished.size();
  api::Simulation::step();
  ++step_count_;
  time_s_ = api::Simulation::getTime();

  events_ = StepEvents{};
  const libsumo::TraCIResults sim = api::Simulation::getSubscriptionResults();
  events_.departed = asStringList(sim, libsumo::VAR_DEPARTED_VEHICLES_IDS);
  events_.arrived = asStringList(sim, libsumo::VAR_ARRIVED_VEHICLES_IDS);
  events_.collided = asStringList(sim, libsumo::VAR_COLLIDING_VEHICLES_IDS);
  events_.teleported = asStringList(sim, libsumo::VAR_TELEPORT_STARTING_VEHICLES_IDS);
  const double loaded = asDouble(sim, libsumo::VAR_LOADED_VEHICLES_NUMBER);
  if (loaded > 0.0) loaded_vehicles_ += static_cast<std::uint64_t>(loaded);
  departed_vehicles_ += events_.departed.size();
  // A vehicle colliding on two lanes at once is listed twice.
  std::sort(events_.collided.begin(), events_.collided.end());
  events_.collided.erase(std::unique(events_.collided.begin(), events_.collided.end()),
                         events_.collided.end());
  if (options_.remove_collided) {
    for (const std::string& id : events_.collided) {
      try {
        // Its subscription first: libsumo would otherwise still serve it at the next
        // step and fail there on a vehicle it no longer knows.
        if (index_.count(id)) api::Vehicle::unsubscribe(id);
        api::Vehicle::remove(id, libsumo::REMOVE_VAPORIZED);
      } catch (const std::exception&) {
        // Already gone (e.g. it arrived in the same step): nothing to remove.
      }
    }
  }
  // Colliding vehicles are removed (by SUMO or above) and may also be listed as arrived,
  // now or in the next step; each leaves once, and only vehicles still tracked arrive.
  for (const std::string& id : events_.collided) removeVehicle(id, &events_.removed);
  for (const std::string& id : events_.teleported) removeVehicle(id, &events_.removed);
  events_.arrived.erase(std::remove_if(events_.arrived.begin(), events_.arrived.end(),
                                       [this](const std::string& id) { return !index_.count(id); }),
                        events_.arrived.end());
  for (const std::string& id : events_.arrived) removeVehicle(id, &events_.removed);
  for (const std::string& id : events_.departed) {
    // A vehicle that collided in the step it departed in was removed above.
    if (options_.remove_collided &&
        std::binary_search(events_.collided.begin(), events_.collided.end(), id))
      continue;
    onDeparted(id);
  }
  readVehicles();
  updateZones();
  return events_;
}

void SumoSession::updateZones() {
  if (options_.guard_busy_speed_share <= 0.0) return;
  const std::size_t n = road_->clusters().size();
  if (zone_speed_share_.size() != n) {
    zone_speed_share_.assign(n, 1.0);  // an empty road is free
    zone_busy_.assign(n, false);
  }
  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for (const VehicleRecord& v : vehicles_) {
    if (v.part != RoadPart::kMainline || v.lane < 1 || v.max_speed_mps <= 0.0) continue;
    const int k = zoneOf(v);
    if (k < 0 || k >= static_cast<int>(n)) continue;
    sum[k] += std::min(1.0, v.speed_mps / v.max_speed_mps);
    ++count[k];
  }
  // Exponential smoothing over the window: one jam-free gap or one slow car does not flip it.
  const double alpha = std::min(1.0, step_length_s_ / std::max(step_length_s_, options_.guard_busy_window_s));
  const double leave = std::max(options_.guard_busy_leave_share, options_.guard_busy_speed_share);
  for (std::size_t k = 0; k < n; ++k) {
    if (count[k] > 0) zone_speed_share_[k] += alpha * (sum[k] / count[k] - zone_speed_share_[k]);
    if (zone_speed_share_[k] < options_.guard_busy_speed_share) zone_busy_[k] = true;
    else if (zone_speed_share_[k] > leave) zone_busy_[k] = false;
    ++guard_.zone_steps;
    if (zone_busy_[k]) ++guard_.busy_zone_steps;
  }
}

int SumoSession::zoneOf(const VehicleRecord& v) const {
  return static_cast<int>(v.x_m / options_.cluster_length_m);
}

void SumoSession::holdOwnDriving(VehicleRecord& v) const {
  v.command = options_.own_car_following ? HeldCommand::kNone : HeldCommand::kKeepSpeed;
  v.command_value = v.speed_mps;
}

bool SumoSession::zoneBusy(int cluster) const {
  return cluster >= 0 && cluster < static_cast<int>(zone_busy_.size()) && zone_busy_[cluster];
}

double SumoSession::zoneSpeedShare(int cluster) const {
  return cluster >= 0 && cluster < static_cast<int>(zone_speed_share_.size()) ? zone_speed_share_[cluster] : 1.0;
}

void SumoSession::removeVehicle(const std::string& id, std::vector<VehicleRecord>* removed) {
  auto it = index_.find(id);
  if (it == index_.end()) return;
  const std::size_t i = it->second;
  if (removed) removed->push_back(vehicles_[i]);
  index_.erase(it);
  if (i != vehicles_.size() - 1) {
    vehicles_[i] = std::move(vehicles_.back());
    index_[vehicles_[i].id] = i;
  }
  vehicles_.pop_back();
}

void SumoSession::onDeparted(const std::string& id) {
  VehicleRecord v;
  v.id = id;
  v.type_id = api::Vehicle::getTypeID(id);
  v.route_id = api::Vehicle::getRouteID(id);
  v.is_cav = v.type_id.compare(0, 3, "cav") == 0;
  try {
    parseRouteId(v.route_id, &v.route_kind, &v.entry_cluster, &v.exit_cluster);
  } catch (const std::invalid_argument&) {
    v.route_kind = RouteKind::kMainThrough;  // foreign routes: tracked, never controlled
  }
  v.length_m = api::Vehicle::getLength(id);
  v.width_m = api::Vehicle::getWidth(id);
  v.max_speed_mps = api::Vehicle::getMaxSpeed(id);
  api::Vehicle::subscribe(id, vehicleVariables());
  if (v.is_cav && options_.cav_max_accel_mps2 > 0.0) api::Vehicle::setAccel(id, options_.cav_max_accel_mps2);
  if (v.is_cav && options_.cav_max_decel_mps2 > 0.0) api::Vehicle::setDecel(id, options_.cav_max_decel_mps2);
  if (v.is_cav && options_.advisory_control) {
    api::Vehicle::setSpeedMode(id, options_.cav_speed_mode);
    if (options_.assist_mode) {
      // Its own route (to its off-ramp) and its own lane changes; advice rides on top.
      api::Vehicle::setLaneChangeMode(id, options_.assist_lane_change_mode);
    } else {
      v.merge_mode = options_.own_merge && v.entry_cluster >= 0;  // ramp CAVs start on a ramp
      api::Vehicle::setLaneChangeMode(id, options_.cav_lane_change_mode | (v.merge_mode ? 1 : 0));
      // Controlled CAVs drive towards the mainline end; the bridge switches the target to the
      // off-ramp only once the CAV is in lane 1 just before it, so a CAV that does not get
      // there in time really misses its exit (SUMO's strategic changes are off).
      if (v.exit_cluster >= 0 && !end_edge_.empty()) api::Vehicle::changeTarget(id, end_edge_);
    }
  }
  index_[id] = vehicles_.size();
  vehicles_.push_back(std::move(v));
}

void SumoSession::readVehicles() {
  const libsumo::SubscriptionResults all = api::Vehicle::getAllSubscriptionResults();
  for (VehicleRecord& v : vehicles_) {
    auto it = all.find(v.id);
    if (it == all.end()) continue;  // teleporting vehicles are off the road this step
    const libsumo::TraCIResults& r = it->second;
    auto pos = r.find(libsumo::VAR_POSITION);
    if (pos != r.end())
      if (auto p = std::dynamic_pointer_cast<libsumo::TraCIPosition>(pos->second)) {
        const double dx = p->x - v.x_m, dy = p->y - v.map_y_m;
        if (dx * dx + dy * dy > 1e-6) v.heading_rad = std::atan2(dy, dx);
        v.x_m = p->x;
        v.map_y_m = p->y;
      }
    v.speed_mps = asDouble(r, libsumo::VAR_SPEED);
    v.accel_mps2 = asDouble(r, libsumo::VAR_ACCELERATION);
    v.lateral_speed_mps = asDouble(r, libsumo::VAR_SPEED_LAT);
    splitLaneId(asString(r, libsumo::VAR_LANE_ID), &v.edge, &v.sumo_lane_index);
    v.lane_pos_m = asDouble(r, libsumo::VAR_LANEPOSITION);
    v.lateral_m = asDouble(r, libsumo::VAR_LANEPOSITION_LAT);  // offset in lane, refined below
    updateDerived(v);
    if (v.lane_change_target != 0) continueLaneChange(v);
    if (v.is_cav && options_.advisory_control) {
      if (v.merge_mode) updateMergeMode(v);
      updateHandback(v);
      if (v.handed_back) ++guard_.handback_steps;
      if (!options_.assist_mode && !v.handed_back) manageExit(v);
    }
  }
}

void SumoSession::updateHandback(VehicleRecord& v) {
  const bool busy_here = options_.guard_busy_handback && !v.merge_mode && road_->hasEdge(v.edge) &&
                         (v.part == RoadPart::kMainline || v.part == RoadPart::kAccelLane) &&
                         zoneBusy(zoneOf(v));
  if (busy_here == v.handed_back) return;
  if (options_.assist_mode) {  // it drives itself already: only its advice is dropped
    v.handed_back = busy_here;
    if (busy_here) ++guard_.handbacks;
    return;
  }
  if (busy_here) {
    // Its route to its off-ramp first: a CAV SUMO cannot route (e.g. mid-junction) waits a step.
    if (v.exit_cluster >= 0 && !v.exit_committed && std::isfinite(v.distance_to_exit_m) && !routeToOwnExit(v))
      return;
    api::Vehicle::setLaneChangeMode(v.id, options_.assist_lane_change_mode);
    v.command = HeldCommand::kNone;  // released in applyHeldCommand
    v.handed_back = true;
    ++guard_.handbacks;
    return;
  }
  // Its zone is free again: lane changes (its exit included) are the RSUs' job once more.
  api::Vehicle::setLaneChangeMode(v.id, options_.cav_lane_change_mode);
  v.handed_back = false;
  if (v.exit_cluster >= 0 && !end_edge_.empty() && std::isfinite(v.distance_to_exit_m)) {
    try {
      api::Vehicle::changeTarget(v.id, end_edge_);
    } catch (const libsumo::TraCIException&) {
      ++route_changes_failed_;  // keeps its route to its exit
    }
    v.exit_committed = false;  // manageExit re-commits it in lane 1 before its off-ramp
  }
}

bool SumoSession::routeToOwnExit(VehicleRecord& v) {
  std::vector<std::string> edges;
  try {
    edges = api::Route::getEdges(v.route_id);
  } catch (const libsumo::TraCIException&) {
    return false;
  }
  auto here = std::find(edges.begin(), edges.end(), v.edge);
  if (here == edges.end()) return false;
  try {
    api::Vehicle::setRoute(v.id, std::vector<std::string>(here, edges.end()));
  } catch (const libsumo::TraCIException&) {
    ++route_changes_failed_;
    return false;
  }
  return true;
}

void SumoSession::updateDerived(VehicleRecord& v) const {
  const double offset_in_lane = v.lateral_m;
  if (!road_->hasEdge(v.edge)) {  // on a junction-internal edge: keep last lane and part
    v.lateral_m = (v.lane - 0.5) * lane_width_m_ + offset_in_lane;
    return;
  }
  const EdgeInfo& e = road_->edge(v.edge);
  v.lane = road_->paperLane(v.edge, v.sumo_lane_index);
  v.on_accel_lane = e.has_accel_lane && v.sumo_lane_index == 0;
  v.part = v.on_accel_lane ? RoadPart::kAccelLane : e.part;
  v.part_cluster = e.cluster;
  v.accel_lane_pos_m = v.on_accel_lane ? v.lane_pos_m : 0.0;
  v.accel_lane_length_m = v.on_accel_lane ? e.x_end_m - e.x_start_m : 0.0;
  // Lateral position from the right edge of lane 1; the acceleration lane and ramps sit
  // at negative values (one lane width to the right of lane 1).
  const int lane_for_lateral = v.part == RoadPart::kMainline ? v.lane : 0;
  v.lateral_m = (lane_for_lateral - 0.5) * lane_width_m_ + offset_in_lane;
  v.distance_to_exit_m = INF;
  if (v.exit_cluster >= 0 && v.part != RoadPart::kOffRamp) {
    const double exit_x = road_->clusters()[v.exit_cluster].exit_x_m;
    if (v.x_m <= exit_x) v.distance_to_exit_m = exit_x - v.x_m;
  }
}

void SumoSession::manageExit(VehicleRecord& v) {
  if (v.exit_cluster < 0 || v.part == RoadPart::kOffRamp) return;
  auto it = pre_exit_edge_.find(v.exit_cluster);
  if (it == pre_exit_edge_.end() || v.edge != it->second) return;
  // On the edge feeding its off-ramp: commit to the exit while in lane 1, withdraw when it
  // leaves lane 1 (the off-ramp only connects from lane 1).
  const bool in_exit_lane = v.lane == 1;
  if (traceCommands() && in_exit_lane != v.exit_committed)
    std::fprintf(stderr, "[sumo t=%.1f] %s %s edge=%s lane=%d pos=%.2f\n", time_s_,
                 in_exit_lane ? "commit-exit" : "withdraw-exit", v.id.c_str(), v.edge.c_str(),
                 v.sumo_lane_index, v.lane_pos_m);
  // SUMO can refuse a route change ("No route found", e.g. a vehicle already past the
  // branch point mid lane change): the vehicle keeps the route it has, the refusal is
  // counted, and the simulation goes on (it once ended a whole training episode).
  try {
    if (in_exit_lane && !v.exit_committed) {
      // An explicit two-edge route: SUMO's router (changeTarget) finds no route to the
      // dead-end ramp edge, but the direct connection from lane 1 exists.
      api::Vehicle::setRoute(v.id, std::vector<std::string>{v.edge, road_->clusters()[v.exit_cluster].off_ramp_edge});
      v.exit_committed = true;
    } else if (!in_exit_lane && v.exit_committed) {
      api::Vehicle::changeTarget(v.id, end_edge_);
      v.exit_committed = false;
    }
  } catch (const libsumo::TraCIException& e) {
    if (route_changes_failed_++ == 0)
      std::fprintf(stderr, "palcas sim: t=%.1f s: SUMO refused a route change of '%s' (%s); it keeps "
                   "its route (counted in route_changes_failed, reported once)\n", time_s_, v.id.c_str(), e.what());
  }
}

void SumoSession::updateMergeMode(VehicleRecord& v) {
  // Strategic changes only until the CAV is on a mainline lane: from then on lane changes
  // (exits included) are the RSUs' job.
  if (v.part != RoadPart::kMainline || v.lane < 1) return;
  api::Vehicle::setLaneChangeMode(v.id, options_.cav_lane_change_mode);
  v.merge_mode = false;
}

void SumoSession::requestLaneChange(VehicleRecord& v, double duration_s) {
  const int index = road_->sumoLaneIndex(v.edge, v.lane_change_target);
  if (index < 0) {  // the target lane does not exist on this edge (e.g. the road narrows)
    v.lane_change_target = 0;
    return;
  }
  if (index_shift_ahead_.count(v.edge) && v.speed_mps > 0.1) {
    // Stop trying before the boundary: past it this index means another lane.
    const EdgeInfo& e = road_->edge(v.edge);
    const double left_m = (e.x_end_m - e.x_start_m) - v.lane_pos_m - v.length_m - 1.0;
    duration_s = std::min(duration_s, std::max(step_length_s_, left_m / v.speed_mps));
  }
  if (traceCommands())
    std::fprintf(stderr, "[sumo t=%.1f] changeLane %s edge=%s lane=%d pos=%.2f -> index %d for %.1f s\n", time_s_,
                 v.id.c_str(), v.edge.c_str(), v.sumo_lane_index, v.lane_pos_m, index, duration_s);
  api::Vehicle::changeLane(v.id, index, duration_s);
  v.lane_change_edge = v.edge;
}

bool SumoSession::wholeOnEdge(const VehicleRecord& v) const {
  // SUMO 1.15's sublane model asserts (MSVehicle::getBackPositionOnLane) and aborts the
  // process when a forced lane change runs while the vehicle straddles a junction: its back
  // still on the edge behind, or its front about to cross into the next edge, whose lane
  // indices may differ (merge edges). Requests are issued only well inside an edge.
  if (!road_->hasEdge(v.edge) || v.lane_pos_m < v.length_m + 0.5) return false;
  if (!index_shift_ahead_.count(v.edge)) return true;
  // The next edge numbers its lanes differently: the whole manoeuvre must fit before it.
  const EdgeInfo& e = road_->edge(v.edge);
  const double left_m = (e.x_end_m - e.x_start_m) - v.lane_pos_m;
  const double time_s = std::max(0.0, v.lane_change_until_s - time_s_);
  return left_m >= v.speed_mps * time_s + v.length_m + 1.0;
}

void SumoSession::boundLaneChangeAcceleration(VehicleRecord& v) {
  const double accel = options_.lane_change_max_accel_mps2, decel = options_.lane_change_max_decel_mps2;
  if ((accel <= 0.0 && decel <= 0.0) || v.lane_change_bounded) return;
  v.own_accel_mps2 = api::Vehicle::getAccel(v.id);
  v.own_decel_mps2 = api::Vehicle::getDecel(v.id);
  if (accel > 0.0) api::Vehicle::setAccel(v.id, std::min(accel, v.own_accel_mps2));
  if (decel > 0.0) api::Vehicle::setDecel(v.id, std::min(decel, v.own_decel_mps2));
  v.lane_change_bounded = true;
}

void SumoSession::restoreLaneChangeAcceleration(VehicleRecord& v) {
  if (!v.lane_change_bounded) return;
  api::Vehicle::setAccel(v.id, v.own_accel_mps2);
  api::Vehicle::setDecel(v.id, v.own_decel_mps2);
  v.lane_change_bounded = false;
}

void SumoSession::continueLaneChange(VehicleRecord& v) {
  if (v.lane == v.lane_change_target || time_s_ >= v.lane_change_until_s - 1e-9) {
    // Done, or dropped after lane_change_duration_s (no safe gap found in time).
    ++(v.lane == v.lane_change_target ? lane_changes_done_ : lane_changes_dropped_);
    if (v.lane == v.lane_change_target) v.last_lane_change_s = time_s_;
    v.lane_change_target = 0;
    restoreLaneChangeAcceleration(v);
    return;
  }
  updateLaneChangeBound(v);
  if (v.edge != v.lane_change_edge && wholeOnEdge(v))
    requestLaneChange(v, v.lane_change_until_s - time_s_);
}

double SumoSession::guardFloorMps(const VehicleRecord& v) const {
  // In a busy zone the floor is the allowed speed itself: advice slows nobody there, the
  // zone's CAVs drive themselves (only route-serving lane changes are still carried out).
  const bool busy = zoneBusy(zoneOf(v));
  const double share = busy ? options_.guard_busy_floor_speed_share : options_.guard_floor_speed_share;
  if (share <= 0.0) return 0.0;
  return share * std::min(v.max_speed_mps, api::Vehicle::getAllowedSpeed(v.id));
}

void SumoSession::updateLaneChangeBound(VehicleRecord& v) {
  ++guard_.lane_change_steps;
  if (options_.guard_floor_speed_share > 0.0 && v.speed_mps < guardFloorMps(v)) {
    // Queued or slowed down: the change must not also hold back how fast it gets going.
    ++guard_.lane_change_released_steps;
    restoreLaneChangeAcceleration(v);
    return;
  }
  boundLaneChangeAcceleration(v);
}

void SumoSession::applyAdvisory(const std::string& id, int action_code, double accel_mps2) {
  auto it = index_.find(id);
  if (it == index_.end()) throw std::invalid_argument("applyAdvisory: unknown vehicle '" + id + "'");
  VehicleRecord& v = vehicles_[it->second];
  if (!isValidActionCode(action_code))
    throw std::invalid_argument("applyAdvisory: unknown action " + std::to_string(action_code));
  const Action action = static_cast<Action>(action_code);
  const bool lane_change = action == Action::kLaneLeft || action == Action::kLaneRight;
  const int target_lane = action == Action::kLaneLeft ? v.lane + 1 : v.lane - 1;
  if (lane_change && road_->hasEdge(v.edge) && road_->sumoLaneIndex(v.edge, target_lane) < 0)
    throw std::invalid_argument("applyAdvisory: vehicle '" + id + "' on edge '" + v.edge +
                                "' has no lane " + std::to_string(target_lane));
  if (action == Action::kAccelerate && !std::isfinite(accel_mps2))
    throw std::invalid_argument("applyAdvisory: vehicle '" + id + "' got acceleration " +
                                std::to_string(accel_mps2));
  if (v.handed_back) {
    // Its zone is busy: it drives itself, route and lane changes included (guard_busy_handback).
    ++guard_.handback_advice_dropped;
    v.command = HeldCommand::kNone;
    return;
  }
  if (lane_change) {
    ++guard_.lane_changes_advised;
    const bool serves_route = (action == Action::kLaneRight && std::isfinite(v.distance_to_exit_m)) ||
                              (action == Action::kLaneLeft && v.on_accel_lane);
    const bool cooling = time_s_ - v.last_lane_change_s < options_.guard_lane_change_cooldown_s;
    const bool busy = zoneBusy(zoneOf(v));
    if (options_.guard_insertion_edge && v.edge == insertion_edge_ && v.lane_change_target == 0) {
      // Where SUMO inserts vehicles: a sideways move there meets vehicles inserted into it.
      ++guard_.lane_changes_insertion_refused;
      holdOwnDriving(v);
      return;
    }
    if (!serves_route && v.lane_change_target == 0 && (cooling || busy)) {
      // Weaving for no need of its own route: moments after its last change, or where the
      // road is busy.
      ++(busy ? guard_.lane_changes_busy_refused : guard_.lane_changes_cooled_down);
      holdOwnDriving(v);
      return;
    }
    v.lane_change_target = target_lane;
    v.lane_change_until_s = time_s_ + options_.lane_change_duration_s;
    updateLaneChangeBound(v);
    // On a junction, or with its back still on one, the request waits until the vehicle is
    // wholly on an edge: continueLaneChange issues it there (within the same time budget).
    v.lane_change_edge.clear();
    if (wholeOnEdge(v)) requestLaneChange(v, options_.lane_change_duration_s);
    holdOwnDriving(v);
  } else if (action == Action::kAccelerate) {
    const double limit = options_.max_advised_accel_mps2;
    v.command = HeldCommand::kAccelerate;
    v.command_value = limit > 0.0 ? std::clamp(accel_mps2, -limit, limit) : accel_mps2;
  } else {  // KEEP
    holdOwnDriving(v);
  }
}

void SumoSession::endCommand(const std::string& id) {
  auto it = index_.find(id);
  if (it == index_.end()) return;
  VehicleRecord& v = vehicles_[it->second];
  if (v.part == RoadPart::kOffRamp) return;
  holdOwnDriving(v);
}

void SumoSession::applyHeldCommand(VehicleRecord& v) {
  if (v.command == HeldCommand::kNone || v.part == RoadPart::kOffRamp) {
    // SUMO's own car following drives it (no command, or it left the mainline): release
    // our last setSpeed once.
    if (v.speed_overridden) api::Vehicle::setSpeed(v.id, -1.0);
    v.speed_overridden = false;
    v.command = HeldCommand::kNone;
    return;
  }
  if (v.command == HeldCommand::kKeepSpeed) {
    v.speed_overridden = true;
    api::Vehicle::setSpeed(v.id, v.command_value);
    return;
  }
  // Holding an acceleration: aim each step at the speed it reaches in one step. With the
  // CAV's safe-speed check on (speed mode 31) that target only ever holds it below what its
  // own car following would do, so the guard bounds how far: never below the floor.
  ++guard_.accelerate_steps;
  double target = std::max(0.0, v.speed_mps + v.command_value * step_length_s_);
  const double floor = guardFloorMps(v);
  if (target < floor) {
    if (v.speed_mps < floor) {
      // Already below it (queued, stopped, blocked): its own driving, at its own rate.
      ++guard_.accelerate_released_steps;
      if (v.speed_overridden) api::Vehicle::setSpeed(v.id, -1.0);
      v.speed_overridden = false;
      return;
    }
    ++guard_.accelerate_floored_steps;
    target = floor;
  }
  v.speed_overridden = true;
  api::Vehicle::setSpeed(v.id, target);
}

}  // namespace palcas::sim
