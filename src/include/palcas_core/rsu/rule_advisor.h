#pragma once
// The rule-based advisory of the `rules` control arm: what an RSU advises a member CAV
// when its advice comes from a documented rule instead of the network. It sits behind the
// same decision interface as the learned policy (RsuController::advise, advice_source
// kRules), so the rule arms drive the same vehicles under the same RSUs, guard and
// actuation as the learned arms, and a comparison isolates what the network adds.
//
// The rule (src/doc/rsu.md, "The rule advisor"), in the spirit of Mehr & Eskandarian's
// threshold lane-change advisory (an exit-bound vehicle is told to move right once the
// distance left falls below what the lanes it must still cross need):
//   1. a CAV on an on-ramp's acceleration lane is advised onto the mainline (LANE_LEFT);
//   2. a CAV bound for an off-ramp in lane l > 1 is advised one lane right once its distance
//      to the exit is below exit_margin_m + exit_distance_per_lane_m * (l - 1);
//   3. a through CAV (no exit ahead) in lanes 1..through_keep_out_lanes is advised one lane
//      left, keeping the lanes that exiting and merging traffic needs clear;
//   4. everything else: KEEP (the CAV's own car-following in its lane).
// It never advises ACCELERATE: speed stays with the CAV's own car-following model.
// Deterministic and stateless: the same vehicle gives the same advice.

#include "palcas_core/common/road_snapshot.h"
#include "palcas_core/learning/pdqn_agent.h"

namespace palcas::rsu {

/// The rule's thresholds (config/rules.yaml; chosen on development seeds).
struct RuleAdvisorOptions {
  /// Distance an exit-bound CAV needs per lane it must still cross to reach lane 1 [m]
  /// (finite, > 0).
  double exit_distance_per_lane_m = 300.0;
  /// Distance kept in hand before the exit on top of the per-lane distances [m]
  /// (finite, >= 0).
  double exit_margin_m = 100.0;
  /// Through CAVs in lanes 1..this are advised one lane left (>= 0; 0 = off).
  int through_keep_out_lanes = 1;
  /// true: a CAV on an acceleration lane is advised onto the mainline.
  bool advise_merge = true;

  /// Throws std::invalid_argument naming the first bad field and its value.
  void validate() const;
};

/// The rule's advice for one member CAV on a road of `num_lanes` mainline lanes. The
/// vehicle is assumed valid (validateVehicle); a lane change the road does not have (left
/// of lane L, right of lane 1) is never returned.
Decision ruleDecision(const VehicleSnapshot& vehicle, int num_lanes, const RuleAdvisorOptions& options);

}  // namespace palcas::rsu
