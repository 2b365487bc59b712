#pragma once
// Measuring an episode from what the bridge publishes: the same code runs live in the node
// and offline on a recorded bag (metrics_from_bag), so the two agree by construction.

#include <palcas_core/metrics/episode_metrics.h>
#include <palcas_core/metrics/outcome_tracker.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/VehicleStateArray.h>

#include <map>
#include <string>
#include <vector>

#include "palcas_sim/road_layout.h"
#include "palcas_sumo_bridge/bridge_options.h"

namespace palcas::bridge {

struct MeasureRules {
  metrics::OutcomeTrackerOptions tracker;
  metrics::EpisodeMetricsOptions metrics;
  /// Edges on which a vehicle is on an off-ramp -> that off-ramp's cluster
  /// (RoadLayout::offRampEdges of the road the bridge built): an exit is judged on the
  /// vehicle's own off-ramp, found by edge, never by its name.
  std::map<std::string, int> off_ramp_edges;
};

/// The rules of the bridge's road: one exit x per cluster (the mainline's end for a cluster
/// without an off-ramp), the off-ramps' edges, the margins and thresholds of `options`.
MeasureRules measureRules(const BridgeOptions& options, const sim::RoadLayout& road);

class EpisodeMeasure {
 public:
  /// @throws std::invalid_argument for invalid rules (see OutcomeTracker).
  explicit EpisodeMeasure(const MeasureRules& rules);

  /// One published state and the vehicles SUMO removed since the previous one.
  /// @return the step's events (to publish). @throws std::invalid_argument for a
  /// malformed state (the step is then not counted).
  std::vector<metrics::VehicleEvent> onStep(const palcas_msgs::VehicleStateArray& states,
                                            const metrics::StepRemovals& removals);

  metrics::EpisodeMetricsAccumulator& metrics() { return metrics_; }
  const metrics::EpisodeMetricsAccumulator& metrics() const { return metrics_; }
  /// Each exit's CAVs by outcome (the open ones censored), index = cluster.
  std::vector<metrics::ExitTally> cavExits() const { return tracker_.cavExits(); }

 private:
  metrics::OutcomeTracker tracker_;
  metrics::EpisodeMetricsAccumulator metrics_;
  std::map<std::string, int> off_ramp_edges_;
};

/// The removal lists of a step, recovered from its published events (COLLISION, TELEPORT,
/// ARRIVED, in their order).
metrics::StepRemovals removalsFromEvents(const palcas_msgs::VehicleEventArray& events);

}  // namespace palcas::bridge
