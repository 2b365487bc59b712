// SumoSession: the vehicle table: who entered and left, what each vehicle is and where (read
// from subscriptions each step), and what follows from it (paper lane, x, distance to exit).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "palcas_sim/sumo_session.h"
#include "sumo_session_api.h"

namespace palcas::sim {

using namespace session_detail;

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
  if (road_->measuredAlongLanes()) {
    // On an own road the route's own ramps say where it enters and leaves, whatever its id
    // (a user's route file may use ids of the r_<from>_<to> form numbered its own way).
    classifyRouteByEdges(*road_, api::Vehicle::getRoute(id), &v.route_kind, &v.entry_cluster, &v.exit_cluster);
  } else {
    try {
      parseRouteId(v.route_id, &v.route_kind, &v.entry_cluster, &v.exit_cluster);
    } catch (const std::invalid_argument&) {
      v.route_kind = RouteKind::kMainThrough;  // foreign routes: tracked, never controlled
    }
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
    const double last_x_m = v.x_m;
    const int last_lane = v.lane;
    const RoadPart last_part = v.part;
    auto pos = r.find(libsumo::VAR_POSITION);
    if (pos != r.end())
      if (auto p = std::dynamic_pointer_cast<libsumo::TraCIPosition>(pos->second)) {
        const double dx = p->x - v.map_x_m, dy = p->y - v.map_y_m;
        if (dx * dx + dy * dy > 1e-6) v.heading_rad = std::atan2(dy, dx);
        v.x_m = p->x;
        v.map_x_m = p->x;
        v.map_y_m = p->y;
      }
    v.speed_mps = asDouble(r, libsumo::VAR_SPEED);
    v.accel_mps2 = asDouble(r, libsumo::VAR_ACCELERATION);
    v.lateral_speed_mps = asDouble(r, libsumo::VAR_SPEED_LAT);
    splitLaneId(asString(r, libsumo::VAR_LANE_ID), &v.edge, &v.sumo_lane_index);
    v.lane_pos_m = asDouble(r, libsumo::VAR_LANEPOSITION);
    v.lateral_m = asDouble(r, libsumo::VAR_LANEPOSITION_LAT);  // offset in lane, refined below
    if (road_->measuredAlongLanes()) v.x_m = road_->xAlongMainline(v.edge, v.lane_pos_m, last_x_m);
    updateDerived(v);
    if (v.lane_change_target != 0) continueLaneChange(v);
    if (v.is_cav && options_.advisory_control) {
      if (v.merge_mode) updateMergeMode(v);
      updateHandback(v);
      guard_.countCavStep(v.guard);
      // Its first read counts as a change too (lane and part were unknown): a CAV that
      // enters the road in a busy zone has just cut into its traffic.
      updateBusyChangeBound(v, v.lane != last_lane || v.part != last_part);
      if (!options_.assist_mode && !v.guard.handed_back) manageExit(v);
    }
  }
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
  if (v.on_accel_lane && road_->measuredAlongLanes() && e.cluster >= 0) {
    // An own road's acceleration lane may span several edges: measured over all of them.
    const ClusterInfo& c = road_->clusters()[e.cluster];
    v.accel_lane_pos_m = v.x_m - c.accel_lane_x_start_m;
    v.accel_lane_length_m = c.accel_lane_length_m;
  }
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

}  // namespace palcas::sim
