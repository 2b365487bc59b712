#pragma once
// Plain, ROS-free mirror of palcas_msgs/VehicleEvent and of VehicleState's route kinds:
// what happened to one vehicle at one step. The outcome tracker produces these events, the
// episode metrics accumulator consumes them, and the bridge converts them to and from the
// message one-to-one (the numeric codes below equal the message constants).

#include <string>

#include "palcas_core/common/road_terms.h"

namespace palcas::metrics {

// The road's vocabulary (common/road_terms.h) under the names the metrics code uses.
using palcas::ROUTE_KIND_COUNT;
using palcas::RouteKind;
using palcas::routeFromRamp;
using palcas::routeHasExit;
using palcas::routeKindFromCode;
using palcas::routeKindName;

/// Kind of a vehicle event (VehicleEvent.DEPARTED ... MERGE_FAILED).
enum class VehicleEventKind : int {
  kDeparted = 0,     ///< first seen on the road
  kArrived = 1,      ///< left the network at the end of its route
  kCollision = 2,    ///< involved in a collision (removed by SUMO)
  kTeleport = 3,     ///< teleported (removed) by SUMO, counted apart from collisions
  kExitOk = 4,       ///< first seen on its own off-ramp
  kExitMissed = 5,   ///< passed its off-ramp (or left by another one)
  kMergeOk = 6,      ///< entered the mainline proper from the on-ramp without stopping
  kMergeFailed = 7,  ///< stopped at the end of the acceleration lane, or removed before merging
};
constexpr int VEHICLE_EVENT_KIND_COUNT = 8;

/// Where a vehicle's exit or merge stands. The outcome tracker (which emits the events) and
/// the episode metrics (which count them) each decide one at most once per vehicle.
enum class Outcome { kUndecided, kSucceeded, kFailed };

/// One event of one vehicle (mirrors palcas_msgs/VehicleEvent).
struct VehicleEvent {
  std::string vehicle_id;
  bool is_cav = false;
  VehicleEventKind kind = VehicleEventKind::kDeparted;
  RouteKind route_kind = RouteKind::kMainThrough;  ///< route kind at first sight
  int cluster = -1;                                ///< cluster where it happened, -1 unknown
  double x_m = 0.0;                                ///< longitudinal position there [m]
};

/// Event kind of a message code 0..7. Throws std::invalid_argument naming the code otherwise.
VehicleEventKind vehicleEventKindFromCode(int code);

/// Names used in logs, JSON and CSV ("departed", "exit_ok", ...); "unknown" for a value
/// outside the enum.
std::string vehicleEventKindName(VehicleEventKind kind);

}  // namespace palcas::metrics
