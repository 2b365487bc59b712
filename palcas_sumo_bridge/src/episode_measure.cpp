#include "palcas_sumo_bridge/episode_measure.h"

#include "palcas_sumo_bridge/msg_conversion.h"

namespace palcas::bridge {

MeasureRules measureRules(const BridgeOptions& o, const sim::RoadLayout& road) {
  MeasureRules rules;
  for (const sim::ClusterInfo& c : road.clusters())
    rules.tracker.exit_x_m.push_back(c.off_ramp_edge.empty() ? road.mainlineLengthM() : c.exit_x_m);
  rules.tracker.miss_margin_m = o.exit_miss_margin_m;
  rules.tracker.stop_speed_mps = o.merge_stop_speed_mps;
  rules.tracker.stop_window_m = o.merge_stop_window_m;
  rules.metrics.comfort_accel_mps2 = o.comfort_threshold_mps2;
  rules.metrics.steady_state_from_s = o.steady_state_from_s;
  rules.off_ramp_edges = road.offRampEdges();
  return rules;
}

EpisodeMeasure::EpisodeMeasure(const MeasureRules& rules)
    : tracker_(rules.tracker), metrics_(rules.metrics), off_ramp_edges_(rules.off_ramp_edges) {}

std::vector<metrics::VehicleEvent> EpisodeMeasure::onStep(
    const palcas_msgs::VehicleStateArray& states, const metrics::StepRemovals& removals) {
  std::vector<metrics::VehicleObservation> observations;
  std::vector<metrics::SpeedSample> samples;
  std::vector<metrics::LaneSample> lanes;
  observations.reserve(states.vehicles.size());
  samples.reserve(states.vehicles.size());
  lanes.reserve(states.vehicles.size());
  for (const auto& s : states.vehicles) {
    observations.push_back(toObservation(s, off_ramp_edges_));
    samples.push_back({s.is_cav != 0, s.speed_mps, s.accel_mps2});
    lanes.push_back({s.id, s.lane});
  }
  std::vector<metrics::VehicleEvent> events = tracker_.update(observations, removals);
  metrics_.addSamples(samples);
  // The step's time first: its events depart and arrive at it (travel times). Its lanes
  // after its events: a vehicle is counted from its DEPARTED on.
  metrics_.setSimSeconds(states.header.stamp.toSec());
  metrics_.addEvents(events);
  metrics_.addLaneSamples(lanes);
  return events;
}

metrics::StepRemovals removalsFromEvents(const palcas_msgs::VehicleEventArray& events) {
  metrics::StepRemovals r;
  for (const auto& e : events.events) {
    if (e.kind == palcas_msgs::VehicleEvent::COLLISION) r.collided.push_back(e.vehicle_id);
    if (e.kind == palcas_msgs::VehicleEvent::TELEPORT) r.teleported.push_back(e.vehicle_id);
    if (e.kind == palcas_msgs::VehicleEvent::ARRIVED) r.arrived.push_back(e.vehicle_id);
  }
  return r;
}

}  // namespace palcas::bridge
