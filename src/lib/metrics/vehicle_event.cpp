#include "palcas_core/metrics/vehicle_event.h"

#include <stdexcept>

namespace palcas::metrics {

VehicleEventKind vehicleEventKindFromCode(int code) {
  if (code < 0 || code >= VEHICLE_EVENT_KIND_COUNT)
    throw std::invalid_argument("vehicle event kind code " + std::to_string(code) +
                                " is not one of 0..7 (VehicleEvent constants)");
  return static_cast<VehicleEventKind>(code);
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
