#include "palcas_core/metrics/vehicle_event.h"

#include <stdexcept>

namespace palcas::metrics {

RouteKind routeKindFromCode(int code) {
  if (code < 0 || code >= ROUTE_KIND_COUNT)
    throw std::invalid_argument("route_kind code " + std::to_string(code) +
                                " is not one of 0..3 (VehicleState.ROUTE_*)");
  return static_cast<RouteKind>(code);
}

VehicleEventKind vehicleEventKindFromCode(int code) {
  if (code < 0 || code >= VEHICLE_EVENT_KIND_COUNT)
    throw std::invalid_argument("vehicle event kind code " + std::to_string(code) +
                                " is not one of 0..7 (VehicleEvent constants)");
  return static_cast<VehicleEventKind>(code);
}

std::string routeKindName(RouteKind kind) {
  switch (kind) {
    case RouteKind::kMainThrough: return "main_through";
    case RouteKind::kMainExit: return "main_exit";
    case RouteKind::kRampThrough: return "ramp_through";
    case RouteKind::kRampExit: return "ramp_exit";
  }
  return "unknown";
}

std::string vehicleEventKindName(VehicleEventKind kind) {
  switch (kind) {
    case VehicleEventKind::kDeparted: return "departed";
    case VehicleEventKind::kArrived: return "arrived";
    case VehicleEventKind::kCollision: return "collision";
    case VehicleEventKind::kTeleport: return "teleport";
    case VehicleEventKind::kExitOk: return "exit_ok";
    case VehicleEventKind::kExitMissed: return "exit_missed";
    case VehicleEventKind::kMergeOk: return "merge_ok";
    case VehicleEventKind::kMergeFailed: return "merge_failed";
  }
  return "unknown";
}

}  // namespace palcas::metrics
