#include "palcas_rsu/msg_conversion.h"

namespace palcas::rsu {

RoadSnapshot toSnapshot(const palcas_msgs::VehicleStateArray& states) {
  RoadSnapshot snapshot;
  snapshot.num_lanes = states.num_lanes;
  snapshot.vehicles.reserve(states.vehicles.size());
  for (const auto& s : states.vehicles) {
    VehicleSnapshot v;
    v.id = s.id;
    v.is_cav = s.is_cav;
    v.lane = s.lane;
    v.x_m = s.x_m;
    v.lateral_m = s.lateral_m;
    v.speed_mps = s.speed_mps;
    v.accel_mps2 = s.accel_mps2;
    v.lateral_speed_mps = s.lateral_speed_mps;
    v.length_m = s.length_m;
    v.width_m = s.width_m;
    v.distance_to_exit_m = s.distance_to_exit_m;
    v.on_accel_lane = s.on_accel_lane;
    v.accel_lane_pos_m = s.accel_lane_pos_m;
    v.accel_lane_length_m = s.accel_lane_length_m;
    v.max_speed_mps = s.max_speed_mps;
    v.driving_itself = s.driving_itself;
    snapshot.vehicles.push_back(std::move(v));
  }
  return snapshot;
}

palcas_msgs::Advisory toMsg(const CavAdvisory& a, uint32_t model_version) {
  palcas_msgs::Advisory m;
  m.vehicle_id = a.vehicle_id;
  m.action = static_cast<uint8_t>(a.decision.action);
  m.accel_mps2 = a.decision.action == Action::kAccelerate ? a.decision.accel_mps2 : 0.0;
  m.model_version = model_version;
  return m;
}

palcas_msgs::ClusterState toMsg(const ClusterSummary& s, const RsuControllerOptions& rsu,
                                uint64_t step, double time_s) {
  palcas_msgs::ClusterState m;
  m.header.stamp = ros::Time(time_s);
  m.step = step;
  m.rsu_id = rsu.rsu_id;
  m.cluster_index = static_cast<uint8_t>(rsu.cluster_index);
  m.x_start_m = rsu.x_start_m;
  m.x_end_m = rsu.x_end_m;
  m.mean_speed_mps = s.mean_speed_mps;
  m.lane_density_veh_per_km = s.lane_density_veh_per_km;
  m.density_veh_per_km = s.density_veh_per_km;
  m.vehicle_count = s.vehicle_count;
  m.cav_count = s.cav_count;
  return m;
}

palcas_msgs::RsuStatus toStatusMsg(const RsuControllerStats& s, const StatusContext& context) {
  palcas_msgs::RsuStatus status;
  status.header = context.header;
  status.step = context.step;
  status.rsu_id = context.rsu_id;
  status.mode = context.train ? "train" : "eval";
  status.decision_ms = context.decision_ms;
  status.members = s.member_count;
  status.action_counts.assign(s.action_counts.begin(), s.action_counts.end());
  status.mean_reward = s.mean_reward;
  status.sum_reward = s.sum_reward;
  status.q_loss = s.q_loss;
  status.param_loss = s.param_loss;
  status.epsilon = s.epsilon;
  status.gradient_steps = s.gradient_steps;
  status.samples_since_federation = s.samples_since_federation;
  status.model_version = s.model_version;
  status.federation_round = s.federation_round;
  status.stale_peers = context.stale_peers;
  status.federation_reachable = context.federation_reachable;
  return status;
}

void addOutcomes(const palcas_msgs::VehicleEventArray& events, VehicleOutcomes& outcomes) {
  for (const auto& e : events.events) {
    if (e.kind >= metrics::VEHICLE_EVENT_KIND_COUNT) continue;  // a newer bridge's kind
    outcomes.add(static_cast<metrics::VehicleEventKind>(e.kind), e.vehicle_id);
  }
}

}  // namespace palcas::rsu
