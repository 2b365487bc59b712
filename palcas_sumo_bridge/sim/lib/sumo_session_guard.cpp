// SumoSession: the advice guard's view of the road: zone speeds, busy zones and the hand-back
// of their CAVs to their own driving, and the floor below which advice may not slow a CAV.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "palcas_sim/sumo_session.h"
#include "sumo_session_api.h"

namespace palcas::sim {

using namespace session_detail;

void SumoSession::updateZones() {
  if (options_.guard_busy_speed_share <= 0.0) return;
  const std::size_t n = road_->clusters().size();
  if (zone_speed_share_.size() != n) {
    // An empty road runs free; or (guard_busy_at_start) a zone is taken as stopped until its
    // smoothed share has risen above the leave share: a window or two of free running.
    zone_speed_share_.assign(n, options_.guard_busy_at_start ? 0.0 : 1.0);
    zone_busy_.assign(n, options_.guard_busy_at_start);
  }
  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for (const VehicleRecord& v : vehicles_) {
    if (v.part != RoadPart::kMainline || v.lane < 1 || v.max_speed_mps <= 0.0) continue;
    const int k = zoneOf(v);
    if (k < 0 || k >= static_cast<int>(n)) continue;
    sum[k] += std::min(1.0, v.speed_mps / v.max_speed_mps);
    ++count[k];
  }
  // Exponential smoothing over the window: one jam-free gap or one slow car does not flip it.
  const double alpha = std::min(1.0, step_length_s_ / std::max(step_length_s_, options_.guard_busy_window_s));
  const double leave = std::max(options_.guard_busy_leave_share, options_.guard_busy_speed_share);
  for (std::size_t k = 0; k < n; ++k) {
    if (count[k] > 0) zone_speed_share_[k] += alpha * (sum[k] / count[k] - zone_speed_share_[k]);
    if (zone_speed_share_[k] < options_.guard_busy_speed_share) zone_busy_[k] = true;
    else if (zone_speed_share_[k] > leave) zone_busy_[k] = false;
    ++guard_.zone_steps;
    if (zone_busy_[k]) ++guard_.busy_zone_steps;
  }
}

int SumoSession::zoneOf(const VehicleRecord& v) const {
  return static_cast<int>(v.x_m / options_.cluster_length_m);
}

void SumoSession::holdOwnDriving(VehicleRecord& v) const {
  v.command = options_.own_car_following ? HeldCommand::kNone : HeldCommand::kKeepSpeed;
  v.command_value = v.speed_mps;
}

bool SumoSession::zoneBusy(int cluster) const {
  return cluster >= 0 && cluster < static_cast<int>(zone_busy_.size()) && zone_busy_[cluster];
}

double SumoSession::zoneSpeedShare(int cluster) const {
  return cluster >= 0 && cluster < static_cast<int>(zone_speed_share_.size()) ? zone_speed_share_[cluster] : 1.0;
}

void SumoSession::updateHandback(VehicleRecord& v) {
  const bool busy_here = options_.guard_busy_handback && !v.merge_mode && road_->hasEdge(v.edge) &&
                         (v.part == RoadPart::kMainline || v.part == RoadPart::kAccelLane) &&
                         zoneBusy(zoneOf(v));
  if (busy_here == v.handed_back) return;
  if (options_.assist_mode) {  // it drives itself already: only its advice is dropped
    v.handed_back = busy_here;
    setBusyGapAcceptance(v, busy_here);
    if (busy_here) ++guard_.handbacks;
    return;
  }
  if (busy_here) {
    // Its route to its off-ramp first: a CAV SUMO cannot route (e.g. mid-junction) waits a step.
    if (v.exit_cluster >= 0 && !v.exit_committed && std::isfinite(v.distance_to_exit_m) && !routeToOwnExit(v))
      return;
    api::Vehicle::setLaneChangeMode(v.id, options_.assist_lane_change_mode);
    setBusyGapAcceptance(v, true);
    v.command = HeldCommand::kNone;  // released in applyHeldCommand
    v.handed_back = true;
    ++guard_.handbacks;
    return;
  }
  // Its zone is free again: lane changes (its exit included) are the RSUs' job once more.
  api::Vehicle::setLaneChangeMode(v.id, options_.cav_lane_change_mode);
  setBusyGapAcceptance(v, false);
  v.handed_back = false;
  if (v.exit_cluster >= 0 && !end_edge_.empty() && std::isfinite(v.distance_to_exit_m)) {
    try {
      api::Vehicle::changeTarget(v.id, end_edge_);
    } catch (const libsumo::TraCIException&) {
      ++route_changes_failed_;  // keeps its route to its exit
    }
    v.exit_committed = false;  // manageExit re-commits it in lane 1 before its off-ramp
  }
}

void SumoSession::setBusyGapAcceptance(VehicleRecord& v, bool busy) const {
  static const char* const kKey = "laneChangeModel.lcAssertive";
  if (busy && options_.guard_busy_lc_assertive > 0.0) {
    if (v.own_lc_assertive.empty()) v.own_lc_assertive = api::Vehicle::getParameter(v.id, kKey);
    api::Vehicle::setParameter(v.id, kKey, std::to_string(options_.guard_busy_lc_assertive));
  } else if (!busy && !v.own_lc_assertive.empty()) {
    api::Vehicle::setParameter(v.id, kKey, v.own_lc_assertive);
    v.own_lc_assertive.clear();
  }
}

void SumoSession::updateBusyChangeBound(VehicleRecord& v, bool switched) {
  const double bound = options_.guard_busy_change_max_accel_mps2;
  if (bound <= 0.0) return;
  // SL2015 moves a vehicle sideways within its lane too (alignment); a change is faster.
  constexpr double kChangingLateralMps = 0.3;
  if (v.handed_back && (switched || std::abs(v.lateral_speed_mps) > kChangingLateralMps))
    v.busy_change_until_s = time_s_ + options_.guard_busy_change_hold_s;
  bool bounded = v.handed_back && time_s_ < v.busy_change_until_s && !v.lane_change_bounded;
  // A slow or queued CAV gets going at its own rate (as the floor lifts an advised change's
  // bound); the free zones' floor, as the busy zones' own is the allowed speed itself.
  if (bounded) bounded = v.speed_mps >= floorMps(v, options_.guard_floor_speed_share);
  if (bounded && !v.busy_change_bounded) {
    v.busy_change_own_accel_mps2 = api::Vehicle::getAccel(v.id);
    api::Vehicle::setAccel(v.id, std::min(bound, v.busy_change_own_accel_mps2));
    v.busy_change_bounded = true;
    ++guard_.busy_change_bounds;
  } else if (!bounded) {
    releaseBusyChangeBound(v);
  }
  if (v.busy_change_bounded) ++guard_.busy_change_bound_steps;
}

void countCollidedUnderGuard(const VehicleRecord& v, GuardCounters* g) {
  if (!v.is_cav) return;
  ++g->collided_cavs;
  if (v.handed_back) ++g->collided_handed_back;
  if (v.busy_change_bounded) ++g->collided_busy_change_bounded;
  if (v.lane_change_target != 0) ++g->collided_advised_change;
  if (v.command == HeldCommand::kAccelerate) ++g->collided_accelerate;
}

void SumoSession::releaseBusyChangeBound(VehicleRecord& v) {
  if (!v.busy_change_bounded) return;
  api::Vehicle::setAccel(v.id, v.busy_change_own_accel_mps2);
  v.busy_change_bounded = false;
}

double SumoSession::guardFloorMps(const VehicleRecord& v) const {
  // In a busy zone the floor is the allowed speed itself: advice slows nobody there, the
  // zone's CAVs drive themselves (only route-serving lane changes are still carried out).
  const bool busy = zoneBusy(zoneOf(v));
  return floorMps(v, busy ? options_.guard_busy_floor_speed_share : options_.guard_floor_speed_share);
}

double SumoSession::floorMps(const VehicleRecord& v, double share) const {
  if (share <= 0.0) return 0.0;
  return share * std::min(v.max_speed_mps, api::Vehicle::getAllowedSpeed(v.id));
}

}  // namespace palcas::sim
