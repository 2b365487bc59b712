// Validation of a CavSituation and its construction from a road snapshot.
#include <cmath>
#include <stdexcept>

#include "palcas_core/reward/reward.h"

namespace palcas {
namespace {

[[noreturn]] void bad(const std::string& key, const std::string& what) {
  throw std::invalid_argument("CAV situation: '" + key + "' " + what);
}
void finite(const std::string& key, double value) {
  if (!std::isfinite(value)) bad(key, "must be finite");
}
void finiteNonNegative(const std::string& key, double value) {
  finite(key, value);
  if (value < 0.0) bad(key, "must be >= 0");
}
void finitePositive(const std::string& key, double value) {
  finite(key, value);
  if (value <= 0.0) bad(key, "must be > 0");
}

}  // namespace

void validateSituation(const CavSituation& s, const RewardParams& params) {
  if (s.num_lanes < 1) bad("num_lanes", "must be >= 1");
  if (s.lane < 0 || s.lane > s.num_lanes)
    bad("lane",
        std::to_string(s.lane) + " does not exist (0.." + std::to_string(s.num_lanes) + ")");
  finiteNonNegative("v", s.v);
  finite("a", s.a);
  finitePositive("length", s.length);
  // +inf = no exit; NaN, -inf and negative distances are errors.
  if (std::isnan(s.distance_to_exit) || s.distance_to_exit < 0.0)
    bad("distance_to_exit", "must be >= 0 or null (no exit)");
  if (s.lead) {
    finite("lead.gap", s.lead->gap);
    finiteNonNegative("lead.v", s.lead->v);
  }
  if (s.follow) {
    finite("follow.gap", s.follow->gap);
    finiteNonNegative("follow.v", s.follow->v);
  }
  if (s.lateral.size() > 4)
    bad("lateral", "has " + std::to_string(s.lateral.size()) + " entries, at most 4");
  for (size_t i = 0; i < s.lateral.size(); ++i) {
    const std::string key = "lateral[" + std::to_string(i) + "].";
    finite(key + "gap", s.lateral[i].gap);
    finite(key + "v_lat_ego", s.lateral[i].v_lat_ego);
    finite(key + "v_lat_other", s.lateral[i].v_lat_other);
    finite(key + "long_gap", s.lateral[i].long_gap);
  }
  if (s.target_lead) {
    finite("target_lead.distance", s.target_lead->distance);
    finiteNonNegative("target_lead.v", s.target_lead->v);
    finitePositive("target_lead.length", s.target_lead->length);
  }
  if (s.target_follow) {
    finite("target_follow.distance", s.target_follow->distance);
    finiteNonNegative("target_follow.v", s.target_follow->v);
  }
  finiteNonNegative("cluster_mean_speed", s.cluster_mean_speed);
  if (s.accel_lane) {
    if (s.lane != 0) bad("accel_lane", "given but lane is " + std::to_string(s.lane) + ", not 0");
    finite("accel_lane.x", s.accel_lane->x);
    finitePositive("accel_lane.length", s.accel_lane->length);
  }
  if (s.v_max) {
    finite("v_max", *s.v_max);
    if (*s.v_max <= params.v_min_ego) bad("v_max", "must be > v_min_ego");
  }
}

CavSituation situationFromSnapshot(const NeighbourFinder& finder, const std::string& cav_id,
                                   const ClusterStats& cluster) {
  const Neighbourhood hood = finder.find(cav_id);  // throws on an unknown id
  const VehicleSnapshot& ego = *hood.ego;
  CavSituation s;
  s.v = ego.speed_mps;
  s.a = ego.accel_mps2;
  s.lane = ego.lane;
  s.num_lanes = finder.numLanes();
  s.length = ego.length_m;
  s.distance_to_exit = ego.distance_to_exit_m;
  s.cluster_mean_speed = cluster.mean_speed_mps;
  if (ego.max_speed_mps > 0.0) s.v_max = ego.max_speed_mps;
  if (ego.on_accel_lane)
    s.accel_lane = CavSituation::AccelLane{ego.accel_lane_pos_m, ego.accel_lane_length_m};

  if (const auto& n = hood.at(NeighbourSlot::kOwnLead))
    s.lead = CavSituation::GapSpeed{n->gap_m, n->vehicle->speed_mps};
  if (const auto& n = hood.at(NeighbourSlot::kOwnFollow))
    s.follow = CavSituation::GapSpeed{n->gap_m, n->vehicle->speed_mps};

  // Lateral RSS frame: positive = from the ego toward the neighbour (see rss.h).
  for (NeighbourSlot slot : {NeighbourSlot::kLeftLead, NeighbourSlot::kLeftFollow,
                             NeighbourSlot::kRightLead, NeighbourSlot::kRightFollow}) {
    const auto& n = hood.at(slot);
    if (!n) continue;
    const VehicleSnapshot& o = *n->vehicle;
    const double toward = o.lateral_m >= ego.lateral_m ? 1.0 : -1.0;
    s.lateral.push_back({std::fabs(o.lateral_m - ego.lateral_m) - 0.5 * (ego.width_m + o.width_m),
                         toward * ego.lateral_speed_mps, toward * o.lateral_speed_mps, n->gap_m});
  }

  // Target lane = the lane toward the exit: the right lane on the mainline (none from
  // lane 1), lane 1 (the left lane) from the acceleration lane.
  const Side target = ego.on_accel_lane ? Side::kLeft : Side::kRight;
  if (ego.lane >= 2 || ego.on_accel_lane) {
    if (const auto& n = hood.at(leadSlot(target)))
      s.target_lead = CavSituation::TargetLead{n->vehicle->x_m - ego.x_m, n->vehicle->speed_mps,
                                               n->vehicle->length_m};
    if (const auto& n = hood.at(followSlot(target)))
      s.target_follow =
          CavSituation::TargetFollow{ego.x_m - n->vehicle->x_m, n->vehicle->speed_mps};
  }
  return s;
}

}  // namespace palcas
