#include "palcas_sumo_bridge/msg_conversion.h"

#include <cmath>

namespace palcas::bridge {

palcas_msgs::VehicleState toMsg(const sim::VehicleRecord& r) {
  palcas_msgs::VehicleState s;
  s.id = r.id;
  s.is_cav = r.is_cav;
  s.lane = static_cast<uint8_t>(r.lane);
  s.edge = r.edge;
  s.sumo_lane_index = static_cast<int8_t>(r.sumo_lane_index);
  s.x_m = r.x_m;
  s.lateral_m = r.lateral_m;
  s.speed_mps = r.speed_mps;
  s.accel_mps2 = r.accel_mps2;
  s.lateral_speed_mps = r.lateral_speed_mps;
  s.length_m = r.length_m;
  s.width_m = r.width_m;
  s.max_speed_mps = r.max_speed_mps;
  s.distance_to_exit_m = r.distance_to_exit_m;
  s.on_accel_lane = r.on_accel_lane;
  s.accel_lane_pos_m = r.accel_lane_pos_m;
  s.accel_lane_length_m = r.accel_lane_length_m;
  s.route_kind = static_cast<uint8_t>(r.route_kind);
  s.entry_cluster = static_cast<int8_t>(r.entry_cluster);
  s.exit_cluster = static_cast<int8_t>(r.exit_cluster);
  s.driving_itself = sim::AdviceGuard::drivesItself(r.guard);
  return s;
}

metrics::VehicleObservation toObservation(const palcas_msgs::VehicleState& s,
                                          const std::map<std::string, int>& off_ramp_edges) {
  metrics::VehicleObservation o;
  o.id = s.id;
  o.is_cav = s.is_cav;
  o.route_kind = metrics::routeKindFromCode(s.route_kind);
  o.exit_cluster = s.exit_cluster;
  o.x_m = s.x_m;
  o.speed_mps = s.speed_mps;
  const auto off_ramp = off_ramp_edges.find(s.edge);
  if (s.on_accel_lane) {
    o.road_part = metrics::RoadPart::kAccelLane;
    o.part_cluster = s.entry_cluster;
    o.accel_lane_pos_m = s.accel_lane_pos_m;
    o.accel_lane_length_m = s.accel_lane_length_m;
  } else if (off_ramp != off_ramp_edges.end()) {
    // An off-ramp of the road, or a junction lane onto one (where the state still shows the
    // mainline lane the vehicle came from): which one is the road's, not the edge's name.
    o.road_part = metrics::RoadPart::kOffRamp;
    o.part_cluster = off_ramp->second;
  } else if (s.lane >= 1) {
    o.road_part = metrics::RoadPart::kMainline;
  } else if (s.exit_cluster >= 0 && !std::isfinite(s.distance_to_exit_m)) {
    // Off the mainline past its exit on an edge the road does not place (an own road's
    // off-ramp of several edges: those after the first): on its off-ramp.
    o.road_part = metrics::RoadPart::kOffRamp;
    o.part_cluster = s.exit_cluster;
  } else {
    o.road_part = metrics::RoadPart::kOnRamp;
    o.part_cluster = s.entry_cluster;
  }
  return o;
}

palcas_msgs::VehicleEvent toMsg(const metrics::VehicleEvent& e) {
  palcas_msgs::VehicleEvent m;
  m.vehicle_id = e.vehicle_id;
  m.is_cav = e.is_cav;
  m.kind = static_cast<uint8_t>(e.kind);
  m.route_kind = static_cast<uint8_t>(e.route_kind);
  m.cluster = static_cast<int8_t>(e.cluster);
  m.x_m = e.x_m;
  return m;
}

metrics::VehicleEvent fromMsg(const palcas_msgs::VehicleEvent& m) {
  metrics::VehicleEvent e;
  e.vehicle_id = m.vehicle_id;
  e.is_cav = m.is_cav;
  e.kind = metrics::vehicleEventKindFromCode(m.kind);
  e.route_kind = metrics::routeKindFromCode(m.route_kind);
  e.cluster = m.cluster;
  e.x_m = m.x_m;
  return e;
}

palcas_msgs::EpisodeMetrics toMsg(const metrics::EpisodeMetrics& m, double wall_seconds) {
  palcas_msgs::EpisodeMetrics out;
  out.sim_seconds = m.sim_seconds;
  out.wall_seconds = wall_seconds;
  out.real_time_factor = wall_seconds > 0.0 ? m.sim_seconds / wall_seconds : 0.0;
  out.efficiency_all_mps = m.efficiency_all_mps;
  out.efficiency_cav_mps = m.efficiency_cav_mps;
  out.collision_rate_pct = m.collision_rate_pct;
  out.dsr_pct = m.dsr_pct;
  out.msr_pct = m.msr_pct;
  out.comfort_share_pct = m.comfort_share_pct;
  out.throughput_vph = m.throughput_vph;
  out.mean_travel_time_s = m.mean_travel_time_s;
  out.lane_changes_per_cav = m.lane_changes_per_cav;
  out.collisions = m.collisions;
  out.cav_collisions = m.cav_collisions;
  out.teleports = m.teleports;
  out.cavs_seen = m.cavs_seen;
  out.exiting_cavs = m.exiting_cavs;
  out.exits_ok = m.exits_ok;
  out.exits_missed = m.exits_missed;
  out.merging_cavs = m.merging_cavs;
  out.merges_ok = m.merges_ok;
  out.arrived = m.arrived;
  out.cav_lane_changes = m.cav_lane_changes;
  out.vehicles_on_road = m.vehicles_on_road;
  out.advisories_applied = m.advisories_applied;
  out.advisories_rejected = m.advisories_rejected;
  out.late_rsu_steps = m.late_rsu_steps;
  return out;
}

metrics::AdvisoryRequest toRequest(const palcas_msgs::Advisory& a, std::uint64_t step,
                                   const std::string& rsu_id) {
  metrics::AdvisoryRequest r;
  r.vehicle_id = a.vehicle_id;
  r.action_code = a.action;
  r.accel_mps2 = a.accel_mps2;
  r.answers_step = step;
  r.rsu_id = rsu_id;
  return r;
}

}  // namespace palcas::bridge
