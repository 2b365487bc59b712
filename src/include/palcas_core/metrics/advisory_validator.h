#pragma once
// The bridge's gate for advisories: decides whether one advisory from an RSU may be applied
// to a vehicle in SUMO, or why not (palcas_msgs/AdvisoryRejection). A pure function of its
// inputs; rules and their order: src/doc/metrics.md.

#include <cstdint>
#include <string>
#include <unordered_set>

namespace palcas::metrics {

/// Why an advisory was refused; values equal AdvisoryRejection's constants.
enum class RejectionReason : int {
  kUnknownVehicle = 0,    ///< no such vehicle on the road
  kNotACav = 1,           ///< the vehicle is human-driven
  kNotFinite = 2,         ///< ACCELERATE with a NaN or infinite acceleration
  kAccelOutOfRange = 3,   ///< ACCELERATE outside [accel_min_mps2, accel_max_mps2]
  kNoSuchLane = 4,        ///< the lane change would leave the mainline lanes
  kStaleStep = 5,         ///< answers an older step than allowed (or a future one)
  kUnknownAction = 6,     ///< action code outside 0..3
  kDuplicate = 7,         ///< the vehicle already received an advisory this step
  /// The whole array's authentication tag is missing or wrong (palcas_core/common/message_auth.h):
  /// counted once per array, before any of its advisories is looked at.
  kUnauthenticated = 8,
  // A valid advisory the advice guard did not carry out (palcas_sim/advice_guard.h): counted
  // and published like the rules above, so one count says what became of every advisory.
  kGuardHandedBack = 9,     ///< its zone is busy: the CAV drives itself, no advice is carried out
  kGuardInsertionEdge = 10, ///< a lane change on the edge where SUMO inserts traffic
  kGuardCooldown = 11,      ///< a lane change moments after its last advised one
  kGuardBusyZone = 12,      ///< a lane change in a busy zone (hand-back off)
  /// SUMO refused the command (libsumo threw): the simulation goes on without it.
  kSumoRefused = 13,
};
constexpr int REJECTION_REASON_COUNT = 14;

/// Name used in logs and JSON ("unknown_vehicle", ..., "sumo_refused"); "unknown" otherwise.
std::string rejectionReasonName(RejectionReason reason);

/// True for the guard's refusals: the advisory was valid, the road's state declined it. They
/// are expected in every run with the guard on, so the bridge logs them at debug level only.
bool isGuardRefusal(RejectionReason reason);

/// One advisory as received (mirrors palcas_msgs/Advisory plus its AdvisoryArray's step/rsu).
struct AdvisoryRequest {
  std::string vehicle_id;
  int action_code = 3;             ///< palcas::Action code, 0..3 expected
  double accel_mps2 = 0.0;         ///< only meaningful for ACCELERATE [m/s^2]
  std::uint64_t answers_step = 0;  ///< bridge step whose state the RSU answered
  std::string rsu_id;
};

/// What the bridge knows of the advised vehicle this step.
struct KnownVehicle {
  bool exists = false;          ///< on the road now; the other fields matter only if true
  bool is_cav = false;
  int lane = 1;                 ///< paper lane 1..num_lanes; 0 = ramp, accel lane or off-ramp
  bool on_accel_lane = false;   ///< on an acceleration lane (then lane == 0)
  /// Mainline lanes at its position: the lanes its edge has (fewer than the road's L where a
  /// lane ends), so this is the trip's one lane check.
  int num_lanes = 5;
};

/// Acceptance limits.
struct AdvisoryLimits {
  double accel_min_mps2 = -4.5;    ///< paper a_min [m/s^2]
  double accel_max_mps2 = 2.6;     ///< paper a_max [m/s^2]
  std::uint64_t max_step_age = 0;  ///< 0 = must answer the current step
};

/// Outcome of validateAdvisory: accepted, or the first failed rule and a detail naming the
/// offending value (e.g. "acceleration 3.1 m/s^2 outside [-4.5, 2.6]").
struct AdvisoryVerdict {
  bool accepted = false;
  RejectionReason reason = RejectionReason::kUnknownVehicle;  ///< meaningful if !accepted
  std::string detail;                                         ///< empty if accepted
};

/// Checks `advisory` at bridge step `current_step`, in this order: UNKNOWN_VEHICLE,
/// NOT_A_CAV, STALE_STEP, DUPLICATE (id in `advised_this_step`, which the caller fills with
/// the ids of the advisories it accepted this step), UNKNOWN_ACTION, then per action:
/// ACCELERATE -> NOT_FINITE, ACCEL_OUT_OF_RANGE (bounds inclusive); LANE_LEFT / LANE_RIGHT ->
/// NO_SUCH_LANE; KEEP has no further rule. The acceleration field is ignored unless the
/// action is ACCELERATE. Throws std::invalid_argument naming the field when `limits` are not
/// finite or min > max, or an existing `vehicle` is inconsistent (num_lanes < 1, lane outside
/// 0..num_lanes, on_accel_lane with lane != 0).
AdvisoryVerdict validateAdvisory(const AdvisoryRequest& advisory, std::uint64_t current_step,
                                 const KnownVehicle& vehicle, const AdvisoryLimits& limits,
                                 const std::unordered_set<std::string>& advised_this_step);

}  // namespace palcas::metrics
