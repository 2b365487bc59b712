#pragma once
// Measuring an episode from what the bridge publishes: the same code runs live in the node
// and offline on a recorded bag (metrics_from_bag), so the two agree by construction.

#include <palcas_core/metrics/episode_metrics.h>
#include <palcas_core/metrics/outcome_tracker.h>
#include <palcas_msgs/VehicleEventArray.h>
#include <palcas_msgs/VehicleStateArray.h>

#include <vector>

namespace palcas::bridge {

struct MeasureRules {
  metrics::OutcomeTrackerOptions tracker;
  metrics::EpisodeMetricsOptions metrics;
};

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

 private:
  metrics::OutcomeTracker tracker_;
  metrics::EpisodeMetricsAccumulator metrics_;
};

/// The removal lists of a step, recovered from its published events (COLLISION, TELEPORT,
/// ARRIVED, in their order).
metrics::StepRemovals removalsFromEvents(const palcas_msgs::VehicleEventArray& events);

}  // namespace palcas::bridge
