#include "palcas_sim/advice_guard.h"

#include <algorithm>
#include <cmath>

namespace palcas::sim {

void AdviceGuard::updateZones(int zones, const std::vector<ZoneSpeedSample>& samples, double step_s) {
  if (!busyZonesOn()) return;
  const std::size_t n = static_cast<std::size_t>(std::max(0, zones));
  if (zone_speed_share_.size() != n) {
    // An empty road runs free; or (busy_at_start) a zone is taken as stopped until its
    // smoothed share has risen above the leave share: a window or two of free running.
    zone_speed_share_.assign(n, options_.busy_at_start ? 0.0 : 1.0);
    zone_busy_.assign(n, options_.busy_at_start);
  }
  std::vector<double> sum(n, 0.0);
  std::vector<int> count(n, 0);
  for (const ZoneSpeedSample& s : samples) {
    if (s.top_speed_mps <= 0.0 || s.zone < 0 || s.zone >= static_cast<int>(n)) continue;
    sum[s.zone] += std::min(1.0, s.speed_mps / s.top_speed_mps);
    ++count[s.zone];
  }
  // Exponential smoothing over the window: one jam-free gap or one slow car does not flip it.
  const double alpha = std::min(1.0, step_s / std::max(step_s, options_.busy_window_s));
  const double leave = std::max(options_.busy_leave_share, options_.busy_speed_share);
  for (std::size_t k = 0; k < n; ++k) {
    if (count[k] > 0) zone_speed_share_[k] += alpha * (sum[k] / count[k] - zone_speed_share_[k]);
    if (zone_speed_share_[k] < options_.busy_speed_share) zone_busy_[k] = true;
    else if (zone_speed_share_[k] > leave) zone_busy_[k] = false;
    ++counters_.zone_steps;
    if (zone_busy_[k]) ++counters_.busy_zone_steps;
  }
}

bool AdviceGuard::zoneBusy(int zone) const {
  return zone >= 0 && zone < static_cast<int>(zone_busy_.size()) && zone_busy_[zone];
}

double AdviceGuard::zoneSpeedShare(int zone) const {
  return zone >= 0 && zone < static_cast<int>(zone_speed_share_.size()) ? zone_speed_share_[zone] : 1.0;
}

double AdviceGuard::floorShare(int zone) const {
  if (!options_.enabled) return 0.0;
  // In a busy zone the floor is its own (1: the allowed speed itself, advice slows nobody
  // there and the zone's CAVs drive themselves).
  return zoneBusy(zone) ? options_.busy_floor_speed_share : options_.floor_speed_share;
}

double AdviceGuard::floorMps(const GuardCav& cav, double share) {
  if (share <= 0.0) return 0.0;
  return share * std::min(cav.top_speed_mps, cav.allowed_speed_mps());
}

AdviceVerdict AdviceGuard::judgeAdvice(const AdviceCase& advice, const GuardMemory& memory) {
  if (drivesItself(memory)) {
    ++counters_.handback_advice_dropped;
    return AdviceVerdict::kDropHandedBack;
  }
  if (!advice.lane_change) return AdviceVerdict::kCarryOut;
  ++counters_.lane_changes_advised;
  if (!options_.enabled || advice.change_under_way) return AdviceVerdict::kCarryOut;
  if (options_.insertion_edge && advice.on_insertion_edge) {
    // Where SUMO inserts vehicles: a sideways move there meets vehicles inserted into it.
    ++counters_.lane_changes_insertion_refused;
    return AdviceVerdict::kRefuseInsertionEdge;
  }
  if (advice.serves_route) return AdviceVerdict::kCarryOut;
  // Weaving for no need of its own route: where the road is busy, or moments after its last
  // change.
  if (zoneBusy(advice.zone)) {
    ++counters_.lane_changes_busy_refused;
    return AdviceVerdict::kRefuseBusy;
  }
  if (advice.time_s - memory.last_lane_change_s < options_.lane_change_cooldown_s) {
    ++counters_.lane_changes_cooled_down;
    return AdviceVerdict::kRefuseCooldown;
  }
  return AdviceVerdict::kCarryOut;
}

HeldAcceleration AdviceGuard::holdAcceleration(const GuardCav& cav, double accel_mps2, double step_s) {
  // Aimed each step at the speed it reaches in one step. With the CAV's safe-speed check on
  // that target only ever holds it below what its own car following would do, so the guard
  // bounds how far: never below the floor.
  ++counters_.accelerate_steps;
  HeldAcceleration out;
  if (options_.enabled && !options_.accelerate_advice) {
    ++counters_.accelerate_own_driving_steps;
    out.kind = HeldAcceleration::Kind::kReleased;
    return out;
  }
  out.target_mps = std::max(0.0, cav.speed_mps + accel_mps2 * step_s);
  const double floor = floorMps(cav);
  if (out.target_mps >= floor) return out;
  if (cav.speed_mps < floor) {
    // Already below it (queued, stopped, blocked): its own driving, at its own rate.
    ++counters_.accelerate_released_steps;
    out.kind = HeldAcceleration::Kind::kReleased;
    return out;
  }
  ++counters_.accelerate_floored_steps;
  out.kind = HeldAcceleration::Kind::kFloored;
  out.target_mps = floor;
  return out;
}

bool AdviceGuard::liftAdvisedChangeBound(const GuardCav& cav) {
  ++counters_.lane_change_steps;
  if (!floorOn() || cav.speed_mps >= floorMps(cav)) return false;
  ++counters_.lane_change_released_steps;
  return true;
}

bool AdviceGuard::wantsHandback(const GuardCav& cav, bool merge_mode, bool on_road,
                                bool mainline_or_accel_lane) const {
  return options_.enabled && options_.busy_handback && !merge_mode && on_road && mainline_or_accel_lane &&
         zoneBusy(cav.zone);
}

HandbackChange AdviceGuard::handbackChange(bool wants, const GuardMemory& memory) {
  if (wants == memory.handed_back) return HandbackChange::kNone;
  return wants ? HandbackChange::kHandBack : HandbackChange::kTakeBack;
}

void AdviceGuard::recordHandback(GuardMemory& memory, bool handed_back, bool assist_mode) {
  memory.handed_back = handed_back;
  memory.advice_kept = handed_back && assist_mode && options_.busy_assist_advice;
  if (handed_back) ++counters_.handbacks;
}

double AdviceGuard::busyChangeBound(const GuardCav& cav, bool switched, double lateral_speed_mps,
                                    bool advised_change_bounded, double time_s, GuardMemory& memory) const {
  const double bound = options_.busy_change_max_accel_mps2;
  if (!options_.enabled || bound <= 0.0) return 0.0;
  // SL2015 moves a vehicle sideways within its lane too (alignment); a change is faster.
  constexpr double kChangingLateralMps = 0.3;
  if (memory.handed_back && (switched || std::abs(lateral_speed_mps) > kChangingLateralMps))
    memory.busy_change_until_s = time_s + options_.busy_change_hold_s;
  if (!memory.handed_back || time_s >= memory.busy_change_until_s || advised_change_bounded) return 0.0;
  // A slow or queued CAV gets going at its own rate (as the floor lifts an advised change's
  // bound); the free zones' floor, as the busy zones' own is the allowed speed itself.
  if (cav.speed_mps < floorMps(cav, options_.floor_speed_share)) return 0.0;
  return bound;
}

void AdviceGuard::recordBusyChangeBound(GuardMemory& memory, bool on) {
  if (on && !memory.busy_change_bounded) ++counters_.busy_change_bounds;
  memory.busy_change_bounded = on;
  if (on) ++counters_.busy_change_bound_steps;
}

void AdviceGuard::countCavStep(const GuardMemory& memory) {
  if (memory.handed_back) ++counters_.handback_steps;
}

}  // namespace palcas::sim
