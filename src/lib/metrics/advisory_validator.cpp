#include "palcas_core/metrics/advisory_validator.h"

#include <cmath>
#include <stdexcept>

#include "palcas_core/common/action.h"
#include "palcas_core/common/checks.h"

namespace palcas::metrics {
namespace {

AdvisoryVerdict reject(RejectionReason reason, std::string detail) {
  return {false, reason, std::move(detail)};
}

void checkInputs(const KnownVehicle& vehicle, const AdvisoryLimits& limits) {
  if (!std::isfinite(limits.accel_min_mps2) || !std::isfinite(limits.accel_max_mps2) ||
      limits.accel_min_mps2 > limits.accel_max_mps2)
    throw std::invalid_argument("AdvisoryLimits: accel_min_mps2 " +
                                common::text(limits.accel_min_mps2) + " / accel_max_mps2 " +
                                common::text(limits.accel_max_mps2) + " must be finite with min <= max");
  if (!vehicle.exists) return;
  if (vehicle.num_lanes < 1)
    throw std::invalid_argument("KnownVehicle: num_lanes " + std::to_string(vehicle.num_lanes) +
                                " must be >= 1");
  if (vehicle.lane < 0 || vehicle.lane > vehicle.num_lanes)
    throw std::invalid_argument("KnownVehicle: lane " + std::to_string(vehicle.lane) +
                                " outside 0.." + std::to_string(vehicle.num_lanes));
  if (vehicle.on_accel_lane && vehicle.lane != 0)
    throw std::invalid_argument("KnownVehicle: on_accel_lane with lane " +
                                std::to_string(vehicle.lane) + " (must be 0)");
}

/// Lane rules (paper lanes, 1 = rightmost .. L = leftmost; the acceleration lane is lane 0
/// to the right of lane 1 and is never a target).
AdvisoryVerdict checkLaneChange(Action action, const KnownVehicle& v) {
  const bool left = action == Action::kLaneLeft;
  const std::string name = left ? "lane_left" : "lane_right";
  if (v.lane == 0 && !v.on_accel_lane)
    return reject(RejectionReason::kNoSuchLane,
                  name + " from a ramp (lane 0, not on an acceleration lane)");
  if (v.lane == 0)  // acceleration lane: left enters lane 1, right leads nowhere
    return left ? AdvisoryVerdict{true, RejectionReason::kUnknownVehicle, ""}
                : reject(RejectionReason::kNoSuchLane,
                         "lane_right from the acceleration lane (lane 0)");
  if (left && v.lane == v.num_lanes)
    return reject(RejectionReason::kNoSuchLane,
                  "lane_left from lane " + std::to_string(v.lane) + ", the leftmost of " +
                      std::to_string(v.num_lanes));
  if (!left && v.lane == 1)
    return reject(RejectionReason::kNoSuchLane,
                  "lane_right from lane 1, the rightmost mainline lane");
  return {true, RejectionReason::kUnknownVehicle, ""};
}

AdvisoryVerdict checkAcceleration(double accel_mps2, const AdvisoryLimits& limits) {
  if (!std::isfinite(accel_mps2))
    return reject(RejectionReason::kNotFinite,
                  "acceleration " + common::text(accel_mps2) + " m/s^2 is not finite");
  if (accel_mps2 < limits.accel_min_mps2 || accel_mps2 > limits.accel_max_mps2)
    return reject(RejectionReason::kAccelOutOfRange,
                  "acceleration " + common::text(accel_mps2) + " m/s^2 outside [" +
                      common::text(limits.accel_min_mps2) + ", " + common::text(limits.accel_max_mps2) + "]");
  return {true, RejectionReason::kUnknownVehicle, ""};
}

}  // namespace

std::string rejectionReasonName(RejectionReason reason) {
  switch (reason) {
    case RejectionReason::kUnknownVehicle: return "unknown_vehicle";
    case RejectionReason::kNotACav: return "not_a_cav";
    case RejectionReason::kNotFinite: return "not_finite";
    case RejectionReason::kAccelOutOfRange: return "accel_out_of_range";
    case RejectionReason::kNoSuchLane: return "no_such_lane";
    case RejectionReason::kStaleStep: return "stale_step";
    case RejectionReason::kUnknownAction: return "unknown_action";
    case RejectionReason::kDuplicate: return "duplicate";
    case RejectionReason::kUnauthenticated: return "unauthenticated";
    case RejectionReason::kGuardHandedBack: return "guard_handed_back";
    case RejectionReason::kGuardInsertionEdge: return "guard_insertion_edge";
    case RejectionReason::kGuardCooldown: return "guard_cooldown";
    case RejectionReason::kGuardBusyZone: return "guard_busy_zone";
    case RejectionReason::kSumoRefused: return "sumo_refused";
  }
  return "unknown";
}

bool isGuardRefusal(RejectionReason reason) {
  return reason == RejectionReason::kGuardHandedBack || reason == RejectionReason::kGuardInsertionEdge ||
         reason == RejectionReason::kGuardCooldown || reason == RejectionReason::kGuardBusyZone;
}

AdvisoryVerdict validateAdvisory(const AdvisoryRequest& advisory, std::uint64_t current_step,
                                 const KnownVehicle& vehicle, const AdvisoryLimits& limits,
                                 const std::unordered_set<std::string>& advised_this_step) {
  checkInputs(vehicle, limits);
  const std::string& id = advisory.vehicle_id;
  if (!vehicle.exists)
    return reject(RejectionReason::kUnknownVehicle, "vehicle '" + id + "' is not on the road");
  if (!vehicle.is_cav)
    return reject(RejectionReason::kNotACav, "vehicle '" + id + "' is human-driven");
  if (advisory.answers_step > current_step)
    return reject(RejectionReason::kStaleStep,
                  "answers step " + std::to_string(advisory.answers_step) +
                      ", a future step (bridge is at step " + std::to_string(current_step) + ")");
  const std::uint64_t age = current_step - advisory.answers_step;
  if (age > limits.max_step_age)
    return reject(RejectionReason::kStaleStep,
                  "answers step " + std::to_string(advisory.answers_step) + ", " +
                      std::to_string(age) + " steps old (bridge at step " +
                      std::to_string(current_step) + ", max age " +
                      std::to_string(limits.max_step_age) + ")");
  if (advised_this_step.count(id) != 0)
    return reject(RejectionReason::kDuplicate,
                  "vehicle '" + id + "' already advised in step " + std::to_string(current_step));
  if (!isValidActionCode(advisory.action_code))
    return reject(RejectionReason::kUnknownAction,
                  "action code " + std::to_string(advisory.action_code) + " not in 0..3");
  const auto action = static_cast<Action>(advisory.action_code);
  switch (action) {
    case Action::kAccelerate: return checkAcceleration(advisory.accel_mps2, limits);
    case Action::kLaneLeft:
    case Action::kLaneRight: return checkLaneChange(action, vehicle);
    case Action::kKeep: break;
  }
  return {true, RejectionReason::kUnknownVehicle, ""};
}

}  // namespace palcas::metrics
