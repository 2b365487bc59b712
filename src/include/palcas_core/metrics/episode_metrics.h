#pragma once
// Running measures of one episode (paper, "Simulation Results"): efficiency,
// CR, DSR, MSR, comfort share and the counters of palcas_msgs/EpisodeMetrics, from speed /
// acceleration samples, VehicleEvents and bridge counters. Deterministic in what it is fed,
// so a recorded bag reproduces the live numbers. Rules: src/doc/metrics.md.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "palcas_core/metrics/advisory_validator.h"
#include "palcas_core/metrics/vehicle_event.h"

namespace palcas::metrics {

/// palcas_msgs/EpisodeMetrics without header, step, wall_seconds and real_time_factor (the
/// bridge fills those). A percentage or mean of an empty denominator is NaN.
struct EpisodeMetrics {
  double sim_seconds = 0.0;
  double efficiency_all_mps = 0.0;  ///< mean speed of all vehicle samples [m/s]
  double efficiency_cav_mps = 0.0;  ///< mean speed of CAV samples [m/s]
  double collision_rate_pct = 0.0;  ///< 100 * cav_collisions / cavs_seen
  double dsr_pct = 0.0;             ///< 100 * exits_ok / exiting_cavs
  double msr_pct = 0.0;             ///< 100 * merges_ok / merging_cavs
  double comfort_share_pct = 0.0;   ///< 100 * (CAV samples with |a| <= a_th) / CAV samples
  double throughput_vph = 0.0;      ///< 3600 * arrived / sim_seconds [veh/h]
  double mean_travel_time_s = 0.0;  ///< mean (arrival - departure time) of arrived vehicles [s]
  double lane_changes_per_cav = 0.0;  ///< cav_lane_changes / cavs_seen
  /// Mean speed of all vehicle samples once the road has filled (steady_state_from_s on) [m/s].
  double efficiency_steady_mps = 0.0;
  /// Vehicle-seconds spent on the road: each vehicle from its DEPARTED to its removal or the
  /// latest time (the wait to enter is the bridge's, SUMO's insertion queue) [veh s].
  double vehicle_seconds_on_road = 0.0;
  /// CAVs bound for an off-ramp / from an on-ramp still on the road with that outcome open:
  /// censored by the episode's end. dsr_censored_pct / msr_censored_pct count them as not
  /// (yet) served: 100 * ok / (decided + censored).
  std::uint32_t exiting_cavs_censored = 0;
  std::uint32_t merging_cavs_censored = 0;
  double dsr_censored_pct = 0.0;
  double msr_censored_pct = 0.0;
  std::uint32_t collisions = 0;     ///< vehicles involved in a collision, all kinds
  std::uint32_t cav_collisions = 0;
  std::uint32_t teleports = 0;      ///< vehicles teleported, all kinds
  std::uint32_t cavs_seen = 0;
  std::uint32_t exiting_cavs = 0;   ///< exit outcome decided: ok + missed + removed before it
  std::uint32_t exits_ok = 0;
  std::uint32_t exits_missed = 0;
  std::uint32_t merging_cavs = 0;   ///< merge outcome decided
  std::uint32_t merges_ok = 0;
  std::uint32_t arrived = 0;           ///< vehicles that left at the end of their route, all kinds
  std::uint32_t cav_lane_changes = 0;  ///< changes of mainline lane (1..L) made by CAVs
  std::uint32_t vehicles_on_road = 0;  ///< departed and not yet removed
  std::uint64_t advisories_applied = 0;
  std::uint64_t advisories_rejected = 0;
  std::uint64_t late_rsu_steps = 0;
};

/// One vehicle at one step, for the batch API.
struct SpeedSample {
  bool is_cav = false;
  double speed_mps = 0.0;   ///< >= 0
  double accel_mps2 = 0.0;  ///< longitudinal, braking negative
};

/// Where one vehicle is at one step, for the lane-change count.
struct LaneSample {
  std::string vehicle_id;
  int lane = 0;  ///< paper lane 1..L on the mainline; 0 = not on a mainline lane
};

struct EpisodeMetricsOptions {
  double comfort_accel_mps2 = 1.47;  ///< a_th of the comfort share [m/s^2] (paper "Comfort")
  /// Samples from this simulation time on count in efficiency_steady_mps [s] (finite, >= 0):
  /// the road has filled by then, so the mean is not diluted by the empty start.
  double steady_state_from_s = 600.0;
};

/// Accumulates one episode. O(1) per sample and per event (hash map of the vehicles on the
/// road). Not thread-safe.
class EpisodeMetricsAccumulator {
 public:
  /// Throws std::invalid_argument when comfort_accel_mps2 or steady_state_from_s is not
  /// finite or negative.
  explicit EpisodeMetricsAccumulator(const EpisodeMetricsOptions& options = {});

  /// One vehicle, one step. Throws std::invalid_argument naming the field for a NaN /
  /// infinite / negative speed or a NaN / infinite acceleration (nothing is added).
  void addSample(bool is_cav, double speed_mps, double accel_mps2);
  /// All samples of a step; all are checked before any is added (same exceptions).
  void addSamples(const std::vector<SpeedSample>& samples);

  /// One event, at the time of the latest setSimSeconds() (a DEPARTED starts the vehicle's
  /// travel time, an ARRIVED ends it). Events of a vehicle without a prior DEPARTED (or after
  /// its removal), a second DEPARTED, and outcomes already decided are ignored and counted
  /// (ignoredEvents()).
  /// Throws std::invalid_argument for an empty id or a kind / route kind outside its enum.
  void addEvent(const VehicleEvent& event);
  /// Events in order; all are checked before any is applied (same exceptions).
  void addEvents(const std::vector<VehicleEvent>& events);

  /// The lanes of a step, after its events (a vehicle counts from its DEPARTED on). A CAV
  /// whose mainline lane differs from its previous mainline lane made a lane change; lane 0
  /// (on-ramp, acceleration lane, off-ramp) is skipped, so merging and exiting are not lane
  /// changes. Vehicles not on the road are skipped. Throws std::invalid_argument for a
  /// negative lane (nothing is added).
  void addLaneSamples(const std::vector<LaneSample>& lanes);

  void addAdvisoriesApplied(std::uint64_t count = 1);
  /// Throws std::invalid_argument for a reason outside the enum.
  void addAdvisoryRejected(RejectionReason reason);
  void addLateRsuStep();
  /// Simulation time of the latest step [s]. Throws std::invalid_argument when it is not
  /// finite, negative, or earlier than the time already set.
  void setSimSeconds(double sim_seconds);

  EpisodeMetrics snapshot() const;
  /// Rejections counted for one reason (0 for a reason outside the enum).
  std::uint64_t rejections(RejectionReason reason) const;
  std::uint64_t ignoredEvents() const { return ignored_events_; }
  /// Back to the state of a new accumulator (options kept).
  void reset();

 private:
  struct Vehicle {
    bool is_cav = false;
    RouteKind route_kind = RouteKind::kMainThrough;
    Outcome exit = Outcome::kUndecided;
    Outcome merge = Outcome::kUndecided;
    double departed_s = 0.0;  ///< simulation time of its DEPARTED
    int mainline_lane = 0;    ///< last paper lane 1..L seen, 0 = none yet
  };

  static void checkEvent(const VehicleEvent& event);
  static void checkSample(const SpeedSample& sample);
  void apply(const SpeedSample& sample);
  void apply(const VehicleEvent& event);
  bool decideExit(Vehicle& v, Outcome outcome, bool missed);
  bool decideMerge(Vehicle& v, Outcome outcome);
  void removeVehicle(std::unordered_map<std::string, Vehicle>::iterator it,
                     VehicleEventKind kind);

  EpisodeMetricsOptions options_;
  double sim_seconds_ = 0.0;
  double speed_sum_all_ = 0.0, speed_sum_cav_ = 0.0, speed_sum_steady_ = 0.0;
  std::uint64_t samples_all_ = 0, samples_cav_ = 0, comfortable_cav_ = 0, samples_steady_ = 0;
  double vehicle_seconds_ = 0.0;  ///< on-road vehicle-seconds up to sim_seconds_
  double travel_time_sum_s_ = 0.0;  ///< over arrived vehicles
  EpisodeMetrics counts_;  ///< counters only; rates are computed in snapshot()
  std::array<std::uint64_t, REJECTION_REASON_COUNT> rejections_{};
  std::uint64_t ignored_events_ = 0;
  std::unordered_map<std::string, Vehicle> on_road_;
};

}  // namespace palcas::metrics
