// SumoSession: carrying advice out: advised lane changes (requested, continued across
// junctions, their acceleration bounded), held ACCELERATE / KEEP commands, as the advice
// guard (advice_guard.h) allows.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "palcas_sim/sumo_session.h"
#include "sumo_session_api.h"

namespace palcas::sim {

using namespace session_detail;

void SumoSession::requestLaneChange(VehicleRecord& v, double duration_s) {
  const int index = road_->sumoLaneIndex(v.edge, v.lane_change_target);
  if (index < 0) {  // the target lane does not exist on this edge (e.g. the road narrows)
    v.lane_change_target = 0;
    return;
  }
  if (index_shift_ahead_.count(v.edge) && v.speed_mps > 0.1) {
    // Stop trying before the boundary: past it this index means another lane.
    const EdgeInfo& e = road_->edge(v.edge);
    const double left_m = (e.x_end_m - e.x_start_m) - v.lane_pos_m - v.length_m - 1.0;
    duration_s = std::min(duration_s, std::max(step_length_s_, left_m / v.speed_mps));
  }
  if (traceCommands())
    std::fprintf(stderr, "[sumo t=%.1f] changeLane %s edge=%s lane=%d pos=%.2f -> index %d for %.1f s\n", time_s_,
                 v.id.c_str(), v.edge.c_str(), v.sumo_lane_index, v.lane_pos_m, index, duration_s);
  api::Vehicle::changeLane(v.id, index, duration_s);
  v.lane_change_edge = v.edge;
}

bool SumoSession::wholeOnEdge(const VehicleRecord& v) const {
  // SUMO 1.15's sublane model asserts (MSVehicle::getBackPositionOnLane) and aborts the
  // process when a forced lane change runs while the vehicle straddles a junction: its back
  // still on the edge behind, or its front about to cross into the next edge, whose lane
  // indices may differ (merge edges). Requests are issued only well inside an edge.
  if (!road_->hasEdge(v.edge) || v.lane_pos_m < v.length_m + 0.5) return false;
  if (!index_shift_ahead_.count(v.edge)) return true;
  // The next edge numbers its lanes differently: the whole manoeuvre must fit before it.
  const EdgeInfo& e = road_->edge(v.edge);
  const double left_m = (e.x_end_m - e.x_start_m) - v.lane_pos_m;
  const double time_s = std::max(0.0, v.lane_change_until_s - time_s_);
  return left_m >= v.speed_mps * time_s + v.length_m + 1.0;
}

void SumoSession::boundLaneChangeAcceleration(VehicleRecord& v) {
  const double accel = options_.lane_change_max_accel_mps2, decel = options_.lane_change_max_decel_mps2;
  if ((accel <= 0.0 && decel <= 0.0) || v.lane_change_bounded) return;
  releaseBusyChangeBound(v);  // its own accel, not the busy zone's bound, is what comes back
  v.own_accel_mps2 = api::Vehicle::getAccel(v.id);
  v.own_decel_mps2 = api::Vehicle::getDecel(v.id);
  if (accel > 0.0) api::Vehicle::setAccel(v.id, std::min(accel, v.own_accel_mps2));
  if (decel > 0.0) api::Vehicle::setDecel(v.id, std::min(decel, v.own_decel_mps2));
  v.lane_change_bounded = true;
}

void SumoSession::restoreLaneChangeAcceleration(VehicleRecord& v) {
  if (!v.lane_change_bounded) return;
  api::Vehicle::setAccel(v.id, v.own_accel_mps2);
  api::Vehicle::setDecel(v.id, v.own_decel_mps2);
  v.lane_change_bounded = false;
}

void SumoSession::continueLaneChange(VehicleRecord& v) {
  if (v.lane == v.lane_change_target || time_s_ >= v.lane_change_until_s - 1e-9) {
    // Done, or dropped after lane_change_duration_s (no safe gap found in time).
    ++(v.lane == v.lane_change_target ? lane_changes_done_ : lane_changes_dropped_);
    if (v.lane == v.lane_change_target) AdviceGuard::laneChangeMade(v.guard, time_s_);
    v.lane_change_target = 0;
    restoreLaneChangeAcceleration(v);
    return;
  }
  updateLaneChangeBound(v);
  if (v.edge != v.lane_change_edge && wholeOnEdge(v))
    requestLaneChange(v, v.lane_change_until_s - time_s_);
}

void SumoSession::updateLaneChangeBound(VehicleRecord& v) {
  // Queued or slowed down: the change must not also hold back how fast it gets going.
  if (guard_.liftAdvisedChangeBound(guardCav(v))) restoreLaneChangeAcceleration(v);
  else boundLaneChangeAcceleration(v);
}

metrics::KnownVehicle SumoSession::known(const std::string& id) const {
  const VehicleRecord* v = find(id);
  // The lanes its edge has, never fewer than the one it is in.
  return knownVehicle(v, v ? std::max(road_->mainLanesOn(v->edge), v->lane) : road_->numMainLanes());
}

AdviceVerdict SumoSession::applyAdvisory(const std::string& id, int action_code, double accel_mps2) {
  auto it = index_.find(id);
  if (it == index_.end()) throw std::invalid_argument("applyAdvisory: unknown vehicle '" + id + "'");
  VehicleRecord& v = vehicles_[it->second];
  if (!isValidActionCode(action_code))
    throw std::invalid_argument("applyAdvisory: unknown action " + std::to_string(action_code));
  const Action action = static_cast<Action>(action_code);
  const bool lane_change = action == Action::kLaneLeft || action == Action::kLaneRight;
  // The target lane was checked once, by validateAdvisory against known(id); should the road
  // narrow before the request is issued, requestLaneChange drops it.
  const int target_lane = action == Action::kLaneLeft ? v.lane + 1 : v.lane - 1;
  if (action == Action::kAccelerate && !std::isfinite(accel_mps2))
    throw std::invalid_argument("applyAdvisory: vehicle '" + id + "' got acceleration " +
                                std::to_string(accel_mps2));
  AdviceCase advice;
  advice.lane_change = lane_change;
  advice.serves_route = (action == Action::kLaneRight && std::isfinite(v.distance_to_exit_m)) ||
                        (action == Action::kLaneLeft && v.on_accel_lane);
  advice.change_under_way = v.lane_change_target != 0;
  advice.on_insertion_edge = v.edge == insertion_edge_;
  advice.zone = zoneOf(v);
  advice.time_s = time_s_;
  const AdviceVerdict verdict = guard_.judgeAdvice(advice, v.guard);
  if (verdict == AdviceVerdict::kDropHandedBack) {
    // Its zone is busy: it drives itself, route and lane changes included.
    v.command = HeldCommand::kNone;
    return verdict;
  }
  if (verdict != AdviceVerdict::kCarryOut) {  // a refused change: it keeps its lane, as under KEEP
    holdOwnDriving(v);
    return verdict;
  }
  if (lane_change) {
    v.lane_change_target = target_lane;
    v.lane_change_until_s = time_s_ + options_.lane_change_duration_s;
    updateLaneChangeBound(v);
    // On a junction, or with its back still on one, the request waits until the vehicle is
    // wholly on an edge: continueLaneChange issues it there (within the same time budget).
    v.lane_change_edge.clear();
    if (wholeOnEdge(v)) requestLaneChange(v, options_.lane_change_duration_s);
    holdOwnDriving(v);
  } else if (action == Action::kAccelerate) {
    const double limit = options_.max_advised_accel_mps2;
    v.command = HeldCommand::kAccelerate;
    v.command_value = limit > 0.0 ? std::clamp(accel_mps2, -limit, limit) : accel_mps2;
  } else {  // KEEP
    holdOwnDriving(v);
  }
  return verdict;
}

void SumoSession::endCommand(const std::string& id) {
  auto it = index_.find(id);
  if (it == index_.end()) return;
  VehicleRecord& v = vehicles_[it->second];
  if (v.part == RoadPart::kOffRamp) return;
  holdOwnDriving(v);
}

void SumoSession::applyHeldCommand(VehicleRecord& v) {
  if (v.command == HeldCommand::kNone || v.part == RoadPart::kOffRamp) {
    // SUMO's own car following drives it (no command, or it left the mainline): release
    // our last setSpeed once.
    if (v.speed_overridden) api::Vehicle::setSpeed(v.id, -1.0);
    v.speed_overridden = false;
    v.command = HeldCommand::kNone;
    return;
  }
  if (v.command == HeldCommand::kKeepSpeed) {
    v.speed_overridden = true;
    api::Vehicle::setSpeed(v.id, v.command_value);
    return;
  }
  // Holding an acceleration: the speed it reaches in one step, as the guard allows.
  const HeldAcceleration held = guard_.holdAcceleration(guardCav(v), v.command_value, step_length_s_);
  if (held.kind == HeldAcceleration::Kind::kReleased) {  // below the floor: its own driving
    if (v.speed_overridden) api::Vehicle::setSpeed(v.id, -1.0);
    v.speed_overridden = false;
    return;
  }
  v.speed_overridden = true;
  api::Vehicle::setSpeed(v.id, held.target_mps);
}

}  // namespace palcas::sim
