#include "palcas_core/rsu/cluster_stats.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace palcas::rsu {

namespace {

void checkZone(double x_start_m, double x_end_m, double empty_zone_speed_mps) {
  std::ostringstream msg;
  if (!std::isfinite(x_start_m) || !std::isfinite(x_end_m) || x_end_m <= x_start_m)
    msg << "cluster zone [x_start_m = " << x_start_m << ", x_end_m = " << x_end_m
        << ") must be finite with x_end_m > x_start_m";
  else if (!std::isfinite(empty_zone_speed_mps) || empty_zone_speed_mps < 0.0)
    msg << "empty_zone_speed_mps = " << empty_zone_speed_mps << " must be finite and >= 0";
  if (!msg.str().empty()) throw std::invalid_argument(msg.str());
}

}  // namespace

ClusterSummary computeClusterSummary(const RoadSnapshot& snapshot, double x_start_m,
                                     double x_end_m, double empty_zone_speed_mps) {
  checkZone(x_start_m, x_end_m, empty_zone_speed_mps);
  if (snapshot.num_lanes < 1)
    throw std::invalid_argument("snapshot num_lanes = " + std::to_string(snapshot.num_lanes) +
                                " must be >= 1");
  const size_t lanes = static_cast<size_t>(snapshot.num_lanes);
  std::vector<uint32_t> lane_count(lanes, 0);
  ClusterSummary out;
  double speed_sum_mps = 0.0;
  for (const VehicleSnapshot& v : snapshot.vehicles) {
    // Mainline lanes only: ramp and acceleration-lane vehicles have no density lane.
    if (v.lane < 1 || v.lane > snapshot.num_lanes) continue;
    if (v.x_m < x_start_m || v.x_m >= x_end_m) continue;  // zone is half-open
    ++lane_count[static_cast<size_t>(v.lane - 1)];
    ++out.vehicle_count;
    if (v.is_cav) ++out.cav_count;
    speed_sum_mps += v.speed_mps;
  }
  // v_bar = (1/N) sum v_i (paper "State Space", s_local); an empty zone flows freely.
  out.mean_speed_mps =
      out.vehicle_count > 0 ? speed_sum_mps / out.vehicle_count : empty_zone_speed_mps;
  // k_l = N_l / (zone length in km) [veh/km]; k = sum_l k_l.
  const double zone_km = (x_end_m - x_start_m) / 1000.0;
  out.lane_density_veh_per_km.resize(lanes);
  for (size_t l = 0; l < lanes; ++l) {
    out.lane_density_veh_per_km[l] = lane_count[l] / zone_km;
  }
  out.density_veh_per_km = out.vehicle_count / zone_km;
  return out;
}

}  // namespace palcas::rsu
