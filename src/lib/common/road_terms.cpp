#include "palcas_core/common/road_terms.h"

#include <stdexcept>

namespace palcas {

RouteKind routeKindFromCode(int code) {
  if (code < 0 || code >= ROUTE_KIND_COUNT)
    throw std::invalid_argument("route_kind code " + std::to_string(code) +
                                " is not one of 0..3 (VehicleState.ROUTE_*)");
  return static_cast<RouteKind>(code);
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

std::string roadPartName(RoadPart part) {
  switch (part) {
    case RoadPart::kMainline: return "mainline";
    case RoadPart::kAccelLane: return "accel_lane";
    case RoadPart::kOnRamp: return "on_ramp";
    case RoadPart::kOffRamp: return "off_ramp";
    case RoadPart::kUnknown: return "unknown";
  }
  return "unknown";
}

}  // namespace palcas
