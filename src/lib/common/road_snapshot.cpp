#include "palcas_core/common/road_snapshot.h"

#include <cmath>
#include <stdexcept>
#include <unordered_set>

namespace palcas {
namespace {

[[noreturn]] void fail(const VehicleSnapshot& v, const std::string& what) {
  throw std::invalid_argument("vehicle '" + v.id + "': " + what);
}

void requireFinite(const VehicleSnapshot& v, const char* field, double value) {
  if (!std::isfinite(value)) fail(v, std::string(field) + " is not finite");
}

}  // namespace

void validateVehicle(const VehicleSnapshot& v, int num_lanes) {
  if (v.id.empty()) throw std::invalid_argument("vehicle with an empty id");
  requireFinite(v, "x_m", v.x_m);
  requireFinite(v, "lateral_m", v.lateral_m);
  requireFinite(v, "speed_mps", v.speed_mps);
  requireFinite(v, "accel_mps2", v.accel_mps2);
  requireFinite(v, "lateral_speed_mps", v.lateral_speed_mps);
  requireFinite(v, "length_m", v.length_m);
  requireFinite(v, "width_m", v.width_m);
  requireFinite(v, "accel_lane_pos_m", v.accel_lane_pos_m);
  requireFinite(v, "accel_lane_length_m", v.accel_lane_length_m);
  requireFinite(v, "max_speed_mps", v.max_speed_mps);
  // +inf is the contract's "no exit"; NaN, -inf and negative values are not.
  if (std::isnan(v.distance_to_exit_m) || v.distance_to_exit_m < 0.0)
    fail(v, "distance_to_exit_m must be >= 0 or +inf");
  if (v.lane < 0 || v.lane > num_lanes)
    fail(v, "lane " + std::to_string(v.lane) + " does not exist (0.." + std::to_string(num_lanes) +
                ")");
  if (v.length_m <= 0.0) fail(v, "length_m must be > 0");
  if (v.width_m <= 0.0) fail(v, "width_m must be > 0");
  if (v.on_accel_lane && v.lane != 0) fail(v, "on_accel_lane set on mainline lane");
}

void validateSnapshot(const RoadSnapshot& snapshot) {
  if (snapshot.num_lanes < 1)
    throw std::invalid_argument("num_lanes must be >= 1, got " +
                                std::to_string(snapshot.num_lanes));
  std::unordered_set<std::string> ids;
  for (const auto& v : snapshot.vehicles) {
    validateVehicle(v, snapshot.num_lanes);
    if (!ids.insert(v.id).second)
      throw std::invalid_argument("duplicate vehicle id '" + v.id + "'");
  }
}

}  // namespace palcas
