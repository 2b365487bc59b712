#include "palcas_core/metrics/outcome_tracker.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_set>
#include <utility>

#include "palcas_core/common/checks.h"

namespace palcas::metrics {
namespace {

std::invalid_argument badField(const std::string& id, const std::string& what) {
  return std::invalid_argument("OutcomeTracker: vehicle '" + id + "': " + what);
}

void requireFinite(const std::string& id, const char* field, double value) {
  if (!std::isfinite(value))
    throw badField(id, common::text(field, " is ", value, ", must be finite"));
}

}  // namespace

OutcomeTracker::OutcomeTracker(OutcomeTrackerOptions options) : options_(std::move(options)) {
  using common::require;
  const char* const bad = "OutcomeTrackerOptions: ";
  for (std::size_t k = 0; k < options_.exit_x_m.size(); ++k)
    require(std::isfinite(options_.exit_x_m[k]), bad, "exit_x_m[", k, "] is ",
            options_.exit_x_m[k], ", must be finite");
  require(std::isfinite(options_.miss_margin_m) && options_.miss_margin_m >= 0.0, bad,
          "miss_margin_m is ", options_.miss_margin_m, ", must be >= 0");
  require(std::isfinite(options_.stop_speed_mps) && options_.stop_speed_mps >= 0.0, bad,
          "stop_speed_mps is ", options_.stop_speed_mps, ", must be >= 0");
  require(std::isfinite(options_.stop_window_m) && options_.stop_window_m >= 0.0, bad,
          "stop_window_m is ", options_.stop_window_m, ", must be >= 0");
  cav_exits_.assign(options_.exit_x_m.size(), ExitTally{});
}

void OutcomeTracker::validateObservation(const VehicleObservation& obs) const {
  const std::string& id = obs.id;
  if (id.empty()) throw std::invalid_argument("OutcomeTracker: observation with an empty id");
  const int route = static_cast<int>(obs.route_kind);
  if (route < 0 || route >= ROUTE_KIND_COUNT)
    throw badField(id, "route_kind " + std::to_string(route) + " is not one of 0..3");
  const int part = static_cast<int>(obs.road_part);
  if (part < 0 || part >= ROAD_PART_COUNT)
    throw badField(id, "road_part " + std::to_string(part) + " is not one of 0..3");
  requireFinite(id, "x_m", obs.x_m);
  requireFinite(id, "speed_mps", obs.speed_mps);
  if (obs.speed_mps < 0.0) throw badField(id, common::text("speed_mps is ", obs.speed_mps, " < 0"));

  const int clusters = static_cast<int>(options_.exit_x_m.size());
  if (routeHasExit(obs.route_kind) && (obs.exit_cluster < 0 || obs.exit_cluster >= clusters))
    throw badField(id, "exit_cluster " + std::to_string(obs.exit_cluster) + " of route " +
                           routeKindName(obs.route_kind) + " is not one of the " +
                           std::to_string(clusters) + " configured exits");
  if (!routeHasExit(obs.route_kind) && obs.exit_cluster != -1)
    throw badField(id, "exit_cluster " + std::to_string(obs.exit_cluster) + " but route " +
                           routeKindName(obs.route_kind) + " has no exit (expected -1)");
  // -1 (unknown) is allowed except on an off-ramp, where the cluster tells its own exit
  // from another one.
  const bool off_ramp = obs.road_part == RoadPart::kOffRamp;
  if (obs.part_cluster < -1 || obs.part_cluster >= clusters || (off_ramp && obs.part_cluster < 0))
    throw badField(id, "part_cluster " + std::to_string(obs.part_cluster) +
                           " is not a cluster 0.." + std::to_string(clusters - 1) +
                           (off_ramp ? " (required on an off-ramp)" : " or -1"));
  if (obs.road_part == RoadPart::kAccelLane) {
    requireFinite(id, "accel_lane_pos_m", obs.accel_lane_pos_m);
    requireFinite(id, "accel_lane_length_m", obs.accel_lane_length_m);
    if (obs.accel_lane_length_m <= 0.0)
      throw badField(id, common::text("accel_lane_length_m is ", obs.accel_lane_length_m,
                                      " on the acceleration lane, must be > 0"));
  }
}

void OutcomeTracker::validate(const std::vector<VehicleObservation>& observations,
                              const StepRemovals& removals) const {
  std::unordered_set<std::string> ids;
  for (const auto& obs : observations) {
    validateObservation(obs);
    if (!ids.insert(obs.id).second)
      throw badField(obs.id, "observed twice in the same step");
  }
  for (const auto* list : {&removals.collided, &removals.teleported, &removals.arrived})
    for (const auto& id : *list)
      if (id.empty()) throw std::invalid_argument("OutcomeTracker: removal with an empty id");
}

std::vector<VehicleEvent> OutcomeTracker::update(
    const std::vector<VehicleObservation>& observations, const StepRemovals& removals) {
  validate(observations, removals);  // throws before anything changes
  std::vector<VehicleEvent> events;
  for (const auto& obs : observations) observe(obs, events);

  std::unordered_set<std::string> removed_this_step;
  const std::pair<const std::vector<std::string>*, VehicleEventKind> lists[] = {
      {&removals.collided, VehicleEventKind::kCollision},
      {&removals.teleported, VehicleEventKind::kTeleport},
      {&removals.arrived, VehicleEventKind::kArrived}};
  for (const auto& [ids, kind] : lists)
    for (const auto& id : *ids)
      if (removed_this_step.insert(id).second) remove(id, kind, events);
  return events;
}

void OutcomeTracker::observe(const VehicleObservation& obs, std::vector<VehicleEvent>& events) {
  auto [it, inserted] = vehicles_.try_emplace(obs.id);
  Tracked& tracked = it->second;
  if (inserted) {
    tracked.is_cav = obs.is_cav;
    tracked.route_kind = obs.route_kind;
    tracked.exit_cluster = obs.exit_cluster;
  }
  tracked.last_cluster = obs.part_cluster;
  tracked.last_x_m = obs.x_m;
  if (inserted)
    events.push_back({obs.id, tracked.is_cav, VehicleEventKind::kDeparted, tracked.route_kind,
                      obs.part_cluster, obs.x_m});
  // A ramp vehicle merges before it can exit, so the merge is decided first.
  if (routeFromRamp(tracked.route_kind) && tracked.merge == Outcome::kUndecided)
    decideMerge(obs, tracked, events);
  if (routeHasExit(tracked.route_kind) && tracked.exit == Outcome::kUndecided)
    decideExit(obs, tracked, events);
}

void OutcomeTracker::decideMerge(const VehicleObservation& obs, Tracked& tracked,
                                 std::vector<VehicleEvent>& events) const {
  VehicleEventKind kind;
  if (obs.road_part == RoadPart::kMainline) {
    tracked.merge = Outcome::kSucceeded;
    kind = VehicleEventKind::kMergeOk;
  } else if (obs.road_part == RoadPart::kAccelLane &&
             obs.speed_mps < options_.stop_speed_mps &&
             obs.accel_lane_length_m - obs.accel_lane_pos_m <= options_.stop_window_m) {
    // Stopped at the end of the acceleration lane (paper MSR): remaining length
    // L_acc - pos <= window and v < v_stop. Failed for good, even if it merges later.
    tracked.merge = Outcome::kFailed;
    kind = VehicleEventKind::kMergeFailed;
  } else {
    return;
  }
  events.push_back({obs.id, tracked.is_cav, kind, tracked.route_kind, obs.part_cluster, obs.x_m});
}

ExitTally& OutcomeTracker::exitTally(const Tracked& tracked) {
  return cav_exits_[static_cast<std::size_t>(tracked.exit_cluster)];
}

void OutcomeTracker::decideExit(const VehicleObservation& obs, Tracked& tracked,
                                std::vector<VehicleEvent>& events) {
  VehicleEventKind kind;
  if (obs.road_part == RoadPart::kOffRamp) {
    // On its own off-ramp: success. On another one: it left the mainline elsewhere, so it
    // can no longer leave at its own exit; counted as missed.
    const bool own = obs.part_cluster == tracked.exit_cluster;
    tracked.exit = own ? Outcome::kSucceeded : Outcome::kFailed;
    kind = own ? VehicleEventKind::kExitOk : VehicleEventKind::kExitMissed;
    if (tracked.is_cav) ++(own ? exitTally(tracked).served : exitTally(tracked).missed);
  } else if (obs.road_part == RoadPart::kMainline &&
             obs.x_m > options_.exit_x_m[static_cast<std::size_t>(tracked.exit_cluster)] +
                           options_.miss_margin_m) {
    // Still on the mainline beyond x_exit + margin: it passed its off-ramp.
    tracked.exit = Outcome::kFailed;
    kind = VehicleEventKind::kExitMissed;
    if (tracked.is_cav) ++exitTally(tracked).missed;
  } else {
    return;
  }
  events.push_back({obs.id, tracked.is_cav, kind, tracked.route_kind, obs.part_cluster, obs.x_m});
}

void OutcomeTracker::remove(const std::string& id, VehicleEventKind kind,
                            std::vector<VehicleEvent>& events) {
  const auto it = vehicles_.find(id);
  if (it == vehicles_.end()) {
    ++ignored_removals_;
    return;
  }
  const Tracked& t = it->second;
  auto event = [&](VehicleEventKind k) {
    events.push_back({id, t.is_cav, k, t.route_kind, t.last_cluster, t.last_x_m});
  };
  // Removed before merging (collision, teleport, or an arrival that never reached the
  // mainline): the merge failed.
  if (routeFromRamp(t.route_kind) && t.merge == Outcome::kUndecided)
    event(VehicleEventKind::kMergeFailed);
  // Arrived without being seen on its own off-ramp: missed. A collision or teleport before
  // the exit is a DSR failure that is neither ok nor missed; there is no event constant for
  // it, the accumulator infers it from the removal event.
  if (routeHasExit(t.route_kind) && t.exit == Outcome::kUndecided &&
      kind == VehicleEventKind::kArrived)
    event(VehicleEventKind::kExitMissed);
  if (t.is_cav && routeHasExit(t.route_kind) && t.exit == Outcome::kUndecided)
    ++(kind == VehicleEventKind::kArrived ? exitTally(t).missed : exitTally(t).lost);
  event(kind);
  vehicles_.erase(it);
}

double ExitTally::servedPct() const {
  const std::size_t bound = exitBound();
  return bound == 0 ? std::numeric_limits<double>::quiet_NaN()
                    : 100.0 * static_cast<double>(served) / static_cast<double>(bound);
}

std::vector<ExitTally> OutcomeTracker::cavExits() const {
  std::vector<ExitTally> tally = cav_exits_;
  for (const auto& [id, t] : vehicles_)
    if (t.is_cav && routeHasExit(t.route_kind) && t.exit == Outcome::kUndecided)
      ++tally[static_cast<std::size_t>(t.exit_cluster)].censored;
  return tally;
}

void OutcomeTracker::reset() {
  vehicles_.clear();
  cav_exits_.assign(options_.exit_x_m.size(), ExitTally{});
  ignored_removals_ = 0;
}

}  // namespace palcas::metrics
