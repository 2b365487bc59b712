#include "palcas_core/metrics/episode_metrics.h"

#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "palcas_core/common/checks.h"

namespace palcas::metrics {
namespace {

constexpr double NOT_A_NUMBER = std::numeric_limits<double>::quiet_NaN();

/// 100 * part / whole, NaN when whole == 0 (an empty denominator has no rate).
double percent(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? NOT_A_NUMBER : 100.0 * static_cast<double>(part) / static_cast<double>(whole);
}

double mean(double sum, std::uint64_t count) {
  return count == 0 ? NOT_A_NUMBER : sum / static_cast<double>(count);
}

}  // namespace

EpisodeMetricsAccumulator::EpisodeMetricsAccumulator(const EpisodeMetricsOptions& options)
    : options_(options) {
  if (!std::isfinite(options_.comfort_accel_mps2) || options_.comfort_accel_mps2 < 0.0)
    throw std::invalid_argument("EpisodeMetricsOptions: comfort_accel_mps2 is " +
                                common::text(options_.comfort_accel_mps2) + ", must be finite and >= 0");
  if (!std::isfinite(options_.steady_state_from_s) || options_.steady_state_from_s < 0.0)
    throw std::invalid_argument("EpisodeMetricsOptions: steady_state_from_s is " +
                                common::text(options_.steady_state_from_s) + ", must be finite and >= 0");
}

void EpisodeMetricsAccumulator::checkSample(const SpeedSample& sample) {
  if (!std::isfinite(sample.speed_mps) || sample.speed_mps < 0.0)
    throw std::invalid_argument("EpisodeMetricsAccumulator: speed_mps is " +
                                common::text(sample.speed_mps) + ", must be finite and >= 0");
  if (!std::isfinite(sample.accel_mps2))
    throw std::invalid_argument("EpisodeMetricsAccumulator: accel_mps2 is " +
                                common::text(sample.accel_mps2) + ", must be finite");
}

void EpisodeMetricsAccumulator::apply(const SpeedSample& sample) {
  // Efficiency (paper "Traffic Efficiency"): mean of v over every (vehicle, step) sample.
  speed_sum_all_ += sample.speed_mps;
  ++samples_all_;
  // Samples come before their step's setSimSeconds: sim_seconds_ is the previous step's time.
  if (sim_seconds_ >= options_.steady_state_from_s) {
    speed_sum_steady_ += sample.speed_mps;
    ++samples_steady_;
  }
  if (!sample.is_cav) return;
  speed_sum_cav_ += sample.speed_mps;
  ++samples_cav_;
  // Comfort (paper "Driving Comfort"): a sample is comfortable when |a| <= a_th.
  if (std::fabs(sample.accel_mps2) <= options_.comfort_accel_mps2) ++comfortable_cav_;
}

void EpisodeMetricsAccumulator::addSample(bool is_cav, double speed_mps, double accel_mps2) {
  const SpeedSample sample{is_cav, speed_mps, accel_mps2};
  checkSample(sample);
  apply(sample);
}

void EpisodeMetricsAccumulator::addSamples(const std::vector<SpeedSample>& samples) {
  for (const auto& s : samples) checkSample(s);
  for (const auto& s : samples) apply(s);
}

void EpisodeMetricsAccumulator::checkEvent(const VehicleEvent& event) {
  if (event.vehicle_id.empty())
    throw std::invalid_argument("EpisodeMetricsAccumulator: event with an empty vehicle_id");
  const int kind = static_cast<int>(event.kind);
  if (kind < 0 || kind >= VEHICLE_EVENT_KIND_COUNT)
    throw std::invalid_argument("EpisodeMetricsAccumulator: event of vehicle '" +
                                event.vehicle_id + "' has kind " + std::to_string(kind) +
                                ", not one of 0..7");
  const int route = static_cast<int>(event.route_kind);
  if (route < 0 || route >= ROUTE_KIND_COUNT)
    throw std::invalid_argument("EpisodeMetricsAccumulator: event of vehicle '" +
                                event.vehicle_id + "' has route_kind " + std::to_string(route) +
                                ", not one of 0..3");
}

void EpisodeMetricsAccumulator::addEvent(const VehicleEvent& event) {
  checkEvent(event);
  apply(event);
}

void EpisodeMetricsAccumulator::addEvents(const std::vector<VehicleEvent>& events) {
  for (const auto& e : events) checkEvent(e);
  for (const auto& e : events) apply(e);
}

bool EpisodeMetricsAccumulator::decideExit(Vehicle& v, Outcome outcome, bool missed) {
  if (!routeHasExit(v.route_kind) || v.exit != Outcome::kUndecided) return false;
  v.exit = outcome;
  if (v.is_cav) {
    ++counts_.exiting_cavs;
    if (outcome == Outcome::kSucceeded) ++counts_.exits_ok;
    if (missed) ++counts_.exits_missed;
  }
  return true;
}

bool EpisodeMetricsAccumulator::decideMerge(Vehicle& v, Outcome outcome) {
  if (!routeFromRamp(v.route_kind) || v.merge != Outcome::kUndecided) return false;
  v.merge = outcome;
  if (v.is_cav) {
    ++counts_.merging_cavs;
    if (outcome == Outcome::kSucceeded) ++counts_.merges_ok;
  }
  return true;
}

void EpisodeMetricsAccumulator::removeVehicle(
    std::unordered_map<std::string, Vehicle>::iterator it, VehicleEventKind kind) {
  Vehicle& v = it->second;
  if (kind == VehicleEventKind::kCollision) {
    ++counts_.collisions;
    if (v.is_cav) ++counts_.cav_collisions;
  } else if (kind == VehicleEventKind::kTeleport) {
    ++counts_.teleports;
  } else if (kind == VehicleEventKind::kArrived) {
    // Throughput and travel time count normal arrivals only (by any route's end).
    ++counts_.arrived;
    travel_time_sum_s_ += sim_seconds_ - v.departed_s;
  }
  // Removed with an outcome still open: a failure (the tracker normally sent it already).
  // Arrived without an exit decided counts as missed; collision / teleport as neither.
  decideMerge(v, Outcome::kFailed);
  decideExit(v, Outcome::kFailed, kind == VehicleEventKind::kArrived);
  on_road_.erase(it);
}

void EpisodeMetricsAccumulator::apply(const VehicleEvent& event) {
  const auto it = on_road_.find(event.vehicle_id);
  if (event.kind == VehicleEventKind::kDeparted) {
    if (it != on_road_.end()) {
      ++ignored_events_;  // second DEPARTED: the first sighting stands
      return;
    }
    Vehicle v;
    v.is_cav = event.is_cav;
    v.route_kind = event.route_kind;
    v.departed_s = sim_seconds_;
    on_road_.emplace(event.vehicle_id, v);
    if (event.is_cav) ++counts_.cavs_seen;
    return;
  }
  if (it == on_road_.end()) {
    ++ignored_events_;  // never departed, or already removed
    return;
  }
  bool used = true;
  switch (event.kind) {
    case VehicleEventKind::kExitOk:
      used = decideExit(it->second, Outcome::kSucceeded, false);
      break;
    case VehicleEventKind::kExitMissed:
      used = decideExit(it->second, Outcome::kFailed, true);
      break;
    case VehicleEventKind::kMergeOk:
      used = decideMerge(it->second, Outcome::kSucceeded);
      break;
    case VehicleEventKind::kMergeFailed:
      used = decideMerge(it->second, Outcome::kFailed);
      break;
    case VehicleEventKind::kCollision:
    case VehicleEventKind::kTeleport:
    case VehicleEventKind::kArrived: removeVehicle(it, event.kind); break;
    case VehicleEventKind::kDeparted: break;  // handled above
  }
  if (!used) ++ignored_events_;
}

void EpisodeMetricsAccumulator::addLaneSamples(const std::vector<LaneSample>& lanes) {
  for (const auto& s : lanes)
    if (s.lane < 0)
      throw std::invalid_argument("EpisodeMetricsAccumulator: vehicle '" + s.vehicle_id +
                                  "' has lane " + std::to_string(s.lane) + ", must be >= 0");
  for (const auto& s : lanes) {
    if (s.lane == 0) continue;  // off the mainline lanes: merging and exiting are not changes
    const auto it = on_road_.find(s.vehicle_id);
    if (it == on_road_.end()) continue;
    Vehicle& v = it->second;
    if (v.mainline_lane != 0 && s.lane != v.mainline_lane && v.is_cav) ++counts_.cav_lane_changes;
    v.mainline_lane = s.lane;
  }
}

void EpisodeMetricsAccumulator::addAdvisoriesApplied(std::uint64_t count) {
  counts_.advisories_applied += count;
}

void EpisodeMetricsAccumulator::addAdvisoryRejected(RejectionReason reason) {
  const int code = static_cast<int>(reason);
  if (code < 0 || code >= REJECTION_REASON_COUNT)
    throw std::invalid_argument("EpisodeMetricsAccumulator: rejection reason " +
                                std::to_string(code) + " is not one of 0..7");
  ++rejections_[static_cast<std::size_t>(code)];
}

void EpisodeMetricsAccumulator::addLateRsuStep() { ++counts_.late_rsu_steps; }

void EpisodeMetricsAccumulator::setSimSeconds(double sim_seconds) {
  if (!std::isfinite(sim_seconds) || sim_seconds < sim_seconds_)
    throw std::invalid_argument("EpisodeMetricsAccumulator: sim_seconds " + common::text(sim_seconds) +
                                " must be finite and >= the previous " + common::text(sim_seconds_));
  // Every vehicle on the road spent the interval on it (those departing now join after).
  vehicle_seconds_ += static_cast<double>(on_road_.size()) * (sim_seconds - sim_seconds_);
  sim_seconds_ = sim_seconds;
}

EpisodeMetrics EpisodeMetricsAccumulator::snapshot() const {
  EpisodeMetrics m = counts_;
  m.sim_seconds = sim_seconds_;
  m.efficiency_all_mps = mean(speed_sum_all_, samples_all_);
  m.efficiency_cav_mps = mean(speed_sum_cav_, samples_cav_);
  m.collision_rate_pct = percent(counts_.cav_collisions, counts_.cavs_seen);
  m.dsr_pct = percent(counts_.exits_ok, counts_.exiting_cavs);
  m.msr_pct = percent(counts_.merges_ok, counts_.merging_cavs);
  m.comfort_share_pct = percent(comfortable_cav_, samples_cav_);
  m.throughput_vph = sim_seconds_ > 0.0 ? 3600.0 * counts_.arrived / sim_seconds_ : NOT_A_NUMBER;
  m.mean_travel_time_s = mean(travel_time_sum_s_, counts_.arrived);
  m.lane_changes_per_cav = counts_.cavs_seen == 0
                               ? NOT_A_NUMBER
                               : static_cast<double>(counts_.cav_lane_changes) / counts_.cavs_seen;
  m.vehicles_on_road = static_cast<std::uint32_t>(on_road_.size());
  m.efficiency_steady_mps = mean(speed_sum_steady_, samples_steady_);
  m.vehicle_seconds_on_road = vehicle_seconds_;
  for (const auto& [id, v] : on_road_) {
    if (!v.is_cav) continue;
    if (routeHasExit(v.route_kind) && v.exit == Outcome::kUndecided) ++m.exiting_cavs_censored;
    if (routeFromRamp(v.route_kind) && v.merge == Outcome::kUndecided) ++m.merging_cavs_censored;
  }
  m.dsr_censored_pct = percent(counts_.exits_ok, std::uint64_t{counts_.exiting_cavs} + m.exiting_cavs_censored);
  m.msr_censored_pct = percent(counts_.merges_ok, std::uint64_t{counts_.merging_cavs} + m.merging_cavs_censored);
  m.advisories_rejected = std::accumulate(rejections_.begin(), rejections_.end(), std::uint64_t{0});
  return m;
}

std::uint64_t EpisodeMetricsAccumulator::rejections(RejectionReason reason) const {
  const int code = static_cast<int>(reason);
  if (code < 0 || code >= REJECTION_REASON_COUNT) return 0;
  return rejections_[static_cast<std::size_t>(code)];
}

void EpisodeMetricsAccumulator::reset() { *this = EpisodeMetricsAccumulator(options_); }

}  // namespace palcas::metrics
