#pragma once
// The road's vocabulary, one definition for the whole suite: which part of the road a
// vehicle is on and what kind of route it drives. The bridge's SUMO session (palcas_sim)
// classifies vehicles with these, the metrics count with them, and the messages carry their
// numeric codes (VehicleState.ROUTE_*), which equal the values below.

#include <string>

namespace palcas {

/// Where a vehicle entered and whether it leaves by an off-ramp (VehicleState.ROUTE_*).
enum class RouteKind : int {
  kMainThrough = 0,  ///< mainline start -> mainline end
  kMainExit = 1,     ///< mainline start -> an off-ramp
  kRampThrough = 2,  ///< an on-ramp -> mainline end
  kRampExit = 3,     ///< an on-ramp -> an off-ramp
};
constexpr int ROUTE_KIND_COUNT = 4;

/// True for routes that end at an off-ramp (they count towards DSR).
constexpr bool routeHasExit(RouteKind kind) {
  return kind == RouteKind::kMainExit || kind == RouteKind::kRampExit;
}

/// True for routes that start on an on-ramp (they count towards MSR).
constexpr bool routeFromRamp(RouteKind kind) {
  return kind == RouteKind::kRampThrough || kind == RouteKind::kRampExit;
}

/// Route kind of a message code 0..3. Throws std::invalid_argument naming the code otherwise.
RouteKind routeKindFromCode(int code);

/// "main_through", "main_exit", "ramp_through", "ramp_exit" (logs, JSON, CSV); "unknown"
/// for a value outside the enum.
std::string routeKindName(RouteKind kind);

/// Which part of the road a vehicle (or an edge) is on.
enum class RoadPart : int {
  kMainline = 0,   ///< a mainline lane 1..L (the mainline proper)
  kAccelLane = 1,  ///< an on-ramp's acceleration lane
  kOnRamp = 2,     ///< an on-ramp before its acceleration lane
  kOffRamp = 3,    ///< an off-ramp (junction-internal lanes leading onto one count as it)
  kUnknown = 4,    ///< an edge outside the road model (the bridge tracks, never controls)
};
/// The parts a tracked vehicle can be on (kUnknown is not one of them).
constexpr int ROAD_PART_COUNT = 4;

/// "mainline", "accel_lane", "on_ramp", "off_ramp", "unknown".
std::string roadPartName(RoadPart part);

}  // namespace palcas
