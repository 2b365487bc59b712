#pragma once
// Where a roadside unit stands in the map: beside the road at its zone's centre, on any road
// (straight or curved, generated or brought), found along the rightmost through lane's shape
// rather than at (road x, fixed y), which is right only on a straight road along +x.

#include <string>
#include <utility>
#include <vector>

namespace palcas::sim {

/// A pose in SUMO's network coordinates (tf frame "map").
struct MapPose {
  double x_m = 0.0;
  double y_m = 0.0;
  double heading_rad = 0.0;  ///< direction of travel, counter-clockwise from +x
};

/// How far right of the rightmost through lane's centre an RSU stands [m]: half a lane and a
/// shoulder (so it is drawn off the carriageway).
constexpr double RSU_SHOULDER_M = 4.0;

/// The point `distance_m` along the polyline `line` (clamped to its ends), moved `right_m` to
/// the right of the direction of travel there, with that direction.
/// @throws std::invalid_argument when the line has fewer than 2 points, a non-finite
///         coordinate or no length, or distance_m / right_m is not finite.
MapPose poseAlong(const std::vector<std::pair<double, double>>& line, double distance_m, double right_m);

}  // namespace palcas::sim
