#pragma once
// Conversions between the bridge's plain types (palcas_sim, palcas_core) and palcas_msgs.
// Free functions in one place; a round-trip test covers them.

#include <palcas_core/metrics/advisory_validator.h>
#include <palcas_core/metrics/episode_metrics.h>
#include <palcas_core/metrics/outcome_tracker.h>
#include <palcas_core/metrics/vehicle_event.h>
#include <palcas_msgs/Advisory.h>
#include <palcas_msgs/EpisodeMetrics.h>
#include <palcas_msgs/VehicleEvent.h>
#include <palcas_msgs/VehicleState.h>

#include <map>
#include <string>

#include "palcas_sim/sumo_session.h"

namespace palcas::bridge {

palcas_msgs::VehicleState toMsg(const sim::VehicleRecord& record);

/// What the outcome tracker needs, derived from the published state only, so that a
/// recorded bag reproduces the live decisions exactly. `off_ramp_edges` (MeasureRules) says
/// which edges are an off-ramp and whose: a vehicle on one is on that off-ramp (junction
/// lanes onto it included, whatever lane the state still shows there).
metrics::VehicleObservation toObservation(const palcas_msgs::VehicleState& state,
                                          const std::map<std::string, int>& off_ramp_edges);

palcas_msgs::VehicleEvent toMsg(const metrics::VehicleEvent& event);
/// @throws std::invalid_argument for an event or route kind code outside its enum.
metrics::VehicleEvent fromMsg(const palcas_msgs::VehicleEvent& event);

/// Fills every field but header and step.
palcas_msgs::EpisodeMetrics toMsg(const metrics::EpisodeMetrics& m, double wall_seconds);

metrics::AdvisoryRequest toRequest(const palcas_msgs::Advisory& advisory, std::uint64_t step,
                                   const std::string& rsu_id);

}  // namespace palcas::bridge
