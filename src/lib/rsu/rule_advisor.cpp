// The rule advisor: the control arm's documented rule (rule_advisor.h).
#include "palcas_core/rsu/rule_advisor.h"

#include <cmath>

#include "palcas_core/common/checks.h"

namespace palcas::rsu {

void RuleAdvisorOptions::validate() const {
  common::require(std::isfinite(exit_distance_per_lane_m) && exit_distance_per_lane_m > 0.0,
                  "RuleAdvisorOptions: exit_distance_per_lane_m = ", exit_distance_per_lane_m,
                  " must be finite and > 0");
  common::require(std::isfinite(exit_margin_m) && exit_margin_m >= 0.0,
                  "RuleAdvisorOptions: exit_margin_m = ", exit_margin_m, " must be finite and >= 0");
  common::require(through_keep_out_lanes >= 0, "RuleAdvisorOptions: through_keep_out_lanes = ",
                  through_keep_out_lanes, " must be >= 0");
}

Decision ruleDecision(const VehicleSnapshot& v, int num_lanes, const RuleAdvisorOptions& o) {
  Decision d;  // KEEP, no acceleration parameter
  if (v.on_accel_lane) {
    if (o.advise_merge) d.action = Action::kLaneLeft;
    return d;
  }
  if (v.lane < 1) return d;  // off the mainline (on- or off-ramp): nothing to advise
  const bool exit_bound = std::isfinite(v.distance_to_exit_m);
  if (exit_bound) {
    const int lanes_to_cross = v.lane - 1;
    const double needed_m = o.exit_margin_m + o.exit_distance_per_lane_m * lanes_to_cross;
    if (lanes_to_cross > 0 && v.distance_to_exit_m < needed_m) d.action = Action::kLaneRight;
    return d;
  }
  if (v.lane <= o.through_keep_out_lanes && v.lane < num_lanes) d.action = Action::kLaneLeft;
  return d;
}

}  // namespace palcas::rsu
