#pragma once
// Turns per-step vehicle observations and SUMO's removal lists into VehicleEvents: who
// entered, who left by its own off-ramp or passed it, who merged from an on-ramp or stopped
// at the end of the acceleration lane, who collided or was teleported (paper, "Simulation
// Results"). Decision rules and their reasons: src/doc/metrics.md.

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "palcas_core/metrics/vehicle_event.h"

namespace palcas::metrics {

// Which part of the road a vehicle is on (common/road_terms.h).
using palcas::ROAD_PART_COUNT;
using palcas::RoadPart;

/// What the bridge sees of one vehicle at one step (a subset of palcas_msgs/VehicleState).
struct VehicleObservation {
  std::string id;
  bool is_cav = false;
  RouteKind route_kind = RouteKind::kMainThrough;
  RoadPart road_part = RoadPart::kMainline;
  int part_cluster = -1;             ///< cluster of the part it is on, -1 = unknown (not
                                     ///< allowed on an off-ramp)
  int exit_cluster = -1;             ///< cluster of its own off-ramp, -1 = no exit
  double x_m = 0.0;                  ///< front bumper along the mainline [m]
  double speed_mps = 0.0;            ///< [m/s], >= 0
  double accel_lane_pos_m = 0.0;     ///< position along the acceleration lane [m] (kAccelLane)
  double accel_lane_length_m = 0.0;  ///< length of that acceleration lane [m] (kAccelLane)
};

/// Vehicles SUMO removed during one step (ids; order inside a list is kept).
struct StepRemovals {
  std::vector<std::string> collided;    ///< involved in a collision
  /// Teleported; SUMO must run with --time-to-teleport.remove so they do not come back.
  std::vector<std::string> teleported;
  std::vector<std::string> arrived;     ///< reached the end of their route
};

/// Parameters of the decision rules.
struct OutcomeTrackerOptions {
  /// x [m] at which cluster k's off-ramp leaves the mainline; its size is the cluster count.
  std::vector<double> exit_x_m;
  /// A vehicle still on the mainline more than this far past its exit x has missed it [m].
  double miss_margin_m = 0.0;
  /// "Stopped" = speed below this [m/s] ...
  double stop_speed_mps = 0.1;
  /// ... within this distance of the end of the acceleration lane [m].
  double stop_window_m = 10.0;
};

/// One exit's CAVs (those whose route ends on that cluster's off-ramp), by outcome. The
/// episode's DSR pools every exit; this tells which RSU's zone lets its exit-bound CAVs pass.
struct ExitTally {
  std::size_t served = 0;    ///< EXIT_OK: seen on their own off-ramp
  std::size_t missed = 0;    ///< EXIT_MISSED: passed it, left by another, or arrived without
  std::size_t lost = 0;      ///< collided or teleported before their exit was decided
  std::size_t censored = 0;  ///< still on the road with the exit open
  std::size_t exitBound() const { return served + missed + lost + censored; }
  /// 100 * served / exitBound(), the censored counted as not served (as dsr_censored_pct);
  /// NaN with no exit-bound CAV.
  double servedPct() const;
};

/// Per-vehicle outcome detector, deterministic in its inputs; memory bounded by the vehicles
/// on the road (a vehicle is forgotten when it is removed). Not thread-safe.
class OutcomeTracker {
 public:
  /// Throws std::invalid_argument naming the option when an exit x or a parameter is not
  /// finite, or a margin / threshold / window is negative.
  explicit OutcomeTracker(OutcomeTrackerOptions options);

  /// Processes one simulation step: first `observations` in their order (DEPARTED on first
  /// sight, then EXIT_* / MERGE_* decisions), then `removals` (collided, teleported, arrived
  /// in that order; an id in several lists counts once, the first list wins). Returns the
  /// step's events in that order. Removal ids never seen are ignored and counted
  /// (ignoredRemovals()).
  /// Throws std::invalid_argument naming the vehicle and field for an empty or repeated id,
  /// NaN / infinite x or speed, negative speed, an enum outside its range, an exit cluster
  /// inconsistent with the route kind or outside the configured exits, a part cluster outside
  /// the clusters (or -1 on an off-ramp), or a non-finite / non-positive acceleration-lane
  /// geometry; or for an empty
  /// removal id. On a throw nothing of the step is applied.
  std::vector<VehicleEvent> update(const std::vector<VehicleObservation>& observations,
                                   const StepRemovals& removals);

  /// Vehicles currently remembered (seen and not yet removed).
  std::size_t trackedVehicles() const { return vehicles_.size(); }
  /// Removal ids of vehicles never seen (or already forgotten) since construction / reset().
  std::size_t ignoredRemovals() const { return ignored_removals_; }
  /// Per cluster (index = cluster, size = the configured exits): the CAVs bound for its
  /// off-ramp since construction / reset(), the open ones as `censored`.
  std::vector<ExitTally> cavExits() const;
  /// Forgets every vehicle, the exit tallies and the ignored-removal count; keeps the options.
  void reset();

 private:
  /// What the tracker remembers of one vehicle; route facts are frozen at first sight, so the
  /// bridge re-routing a vehicle after a missed exit does not change its outcome.
  struct Tracked {
    bool is_cav = false;
    RouteKind route_kind = RouteKind::kMainThrough;
    int exit_cluster = -1;
    Outcome exit = Outcome::kUndecided;
    Outcome merge = Outcome::kUndecided;
    int last_cluster = -1;
    double last_x_m = 0.0;
  };

  void validate(const std::vector<VehicleObservation>& observations,
                const StepRemovals& removals) const;
  void validateObservation(const VehicleObservation& obs) const;
  void observe(const VehicleObservation& obs, std::vector<VehicleEvent>& events);
  void decideExit(const VehicleObservation& obs, Tracked& tracked,
                  std::vector<VehicleEvent>& events);
  ExitTally& exitTally(const Tracked& tracked);
  void decideMerge(const VehicleObservation& obs, Tracked& tracked,
                   std::vector<VehicleEvent>& events) const;
  void remove(const std::string& id, VehicleEventKind kind, std::vector<VehicleEvent>& events);

  OutcomeTrackerOptions options_;
  std::unordered_map<std::string, Tracked> vehicles_;
  std::size_t ignored_removals_ = 0;
  std::vector<ExitTally> cav_exits_;  ///< decided outcomes only; censored filled on query
};

}  // namespace palcas::metrics
