#include "palcas_sumo_bridge/episode_measure.h"

#include "palcas_sumo_bridge/msg_conversion.h"

namespace palcas::bridge {

EpisodeMeasure::EpisodeMeasure(const MeasureRules& rules)
    : tracker_(rules.tracker), metrics_(rules.metrics) {}

std::vector<metrics::VehicleEvent> EpisodeMeasure::onStep(
    const palcas_msgs::VehicleStateArray& states, const metrics::StepRemovals& removals) {
  std::vector<metrics::VehicleObservation> observations;
  std::vector<metrics::SpeedSample> samples;
  std::vector<metrics::LaneSample> lanes;
  observations.reserve(states.vehicles.size());
  samples.reserve(states.vehicles.size());
  lanes.reserve(states.vehicles.size());
  for (const auto& s : states.vehicles) {
    observations.push_back(toObservation(s));
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
