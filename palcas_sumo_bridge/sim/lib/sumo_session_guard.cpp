// SumoSession: the advice guard's decisions (advice_guard.h) fed with what SUMO says and
// carried out in SUMO: zone speeds, the hand-back of busy zones' CAVs to their own driving,
// their gap acceptance and change bound.
#include <algorithm>
#include <cmath>
#include <string>

#include "palcas_sim/sumo_session.h"
#include "sumo_session_api.h"

namespace palcas::sim {

using namespace session_detail;

GuardCav SumoSession::guardCav(const VehicleRecord& v) const {
  GuardCav c;
  c.speed_mps = v.speed_mps;
  c.top_speed_mps = v.max_speed_mps;
  c.zone = zoneOf(v);
  const std::string* id = &v.id;
  c.allowed_speed_mps = [id] { return api::Vehicle::getAllowedSpeed(*id); };
  return c;
}

void SumoSession::updateZones() {
  if (!guard_.busyZonesOn()) return;
  std::vector<ZoneSpeedSample> samples;
  samples.reserve(vehicles_.size());
  for (const VehicleRecord& v : vehicles_)
    if (v.part == RoadPart::kMainline && v.lane >= 1) samples.push_back({zoneOf(v), v.speed_mps, v.max_speed_mps});
  guard_.updateZones(static_cast<int>(road_->clusters().size()), samples, step_length_s_);
}

void SumoSession::holdOwnDriving(VehicleRecord& v) const {
  v.command = options_.own_car_following ? HeldCommand::kNone : HeldCommand::kKeepSpeed;
  v.command_value = v.speed_mps;
}

void SumoSession::updateHandback(VehicleRecord& v) {
  const bool wants = guard_.wantsHandback(guardCav(v), v.merge_mode, road_->hasEdge(v.edge),
                                          v.part == RoadPart::kMainline || v.part == RoadPart::kAccelLane);
  const HandbackChange change = AdviceGuard::handbackChange(wants, v.guard);
  if (change == HandbackChange::kNone) return;
  const bool hand_back = change == HandbackChange::kHandBack;
  if (options_.assist_mode) {  // it drives itself already: only its advice is dropped
    guard_.recordHandback(v.guard, hand_back, true);
    setBusyGapAcceptance(v, hand_back);
    return;
  }
  if (hand_back) {
    // Its route to its off-ramp first: a CAV SUMO cannot route (e.g. mid-junction) waits a step.
    if (v.exit_cluster >= 0 && !v.exit_committed && std::isfinite(v.distance_to_exit_m) && !routeToOwnExit(v))
      return;
    api::Vehicle::setLaneChangeMode(v.id, options_.assist_lane_change_mode);
    setBusyGapAcceptance(v, true);
    v.command = HeldCommand::kNone;  // released in applyHeldCommand
    guard_.recordHandback(v.guard, true);
    return;
  }
  // Its zone is free again: lane changes (its exit included) are the RSUs' job once more.
  api::Vehicle::setLaneChangeMode(v.id, options_.cav_lane_change_mode);
  setBusyGapAcceptance(v, false);
  guard_.recordHandback(v.guard, false);
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
  const double busy_value = guard_.busyLcAssertive();
  if (busy && busy_value > 0.0) {
    if (v.own_lc_assertive.empty()) v.own_lc_assertive = api::Vehicle::getParameter(v.id, kKey);
    api::Vehicle::setParameter(v.id, kKey, std::to_string(busy_value));
  } else if (!busy && !v.own_lc_assertive.empty()) {
    api::Vehicle::setParameter(v.id, kKey, v.own_lc_assertive);
    v.own_lc_assertive.clear();
  }
}

void SumoSession::updateBusyChangeBound(VehicleRecord& v, bool switched) {
  const double bound =
      guard_.busyChangeBound(guardCav(v), switched, v.lateral_speed_mps, v.lane_change_bounded, time_s_, v.guard);
  if (bound > 0.0 && !v.guard.busy_change_bounded) {
    v.busy_change_own_accel_mps2 = api::Vehicle::getAccel(v.id);
    api::Vehicle::setAccel(v.id, std::min(bound, v.busy_change_own_accel_mps2));
  } else if (bound <= 0.0) {
    releaseBusyChangeBound(v);
  }
  guard_.recordBusyChangeBound(v.guard, bound > 0.0);
}

void countCollidedUnderGuard(const VehicleRecord& v, GuardCounters* g) {
  if (!v.is_cav) return;
  ++g->collided_cavs;
  if (v.guard.handed_back) ++g->collided_handed_back;
  if (v.guard.busy_change_bounded) ++g->collided_busy_change_bounded;
  if (v.lane_change_target != 0) ++g->collided_advised_change;
  if (v.command == HeldCommand::kAccelerate) ++g->collided_accelerate;
}

void SumoSession::releaseBusyChangeBound(VehicleRecord& v) {
  if (!v.guard.busy_change_bounded) return;
  api::Vehicle::setAccel(v.id, v.busy_change_own_accel_mps2);
  v.guard.busy_change_bounded = false;
}

}  // namespace palcas::sim
